// SPDX-License-Identifier: AGPL-3.0-or-later
// The only translation unit that instantiates Mesh_3 (slow to compile).
#include "bench/mesh3_baseline.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <iostream>
#include <map>
#include <optional>
#include <streambuf>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_3/initialize_triangulation_from_labeled_image.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/refine_mesh_3.h>
#include <vtkImageData.h>

#include "core/volume/voxel_access.h"

namespace labelmesh::bench {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

// 1 where the voxel holds `label`, 0 elsewhere, placed in physical space.
CGAL::Image_3 binary_image(const volume::LabelVolume& volume, int32_t label) {
  const auto& g = volume.geometry;
  _image* image = _createImage(g.dims[0], g.dims[1], g.dims[2], 1, g.spacing[0], g.spacing[1],
                               g.spacing[2], 1, WK_FIXED, SGN_UNSIGNED);
  image->tx = float(g.origin[0]);
  image->ty = float(g.origin[1]);
  image->tz = float(g.origin[2]);
  auto* out = static_cast<unsigned char*>(image->data);
  vtkImageData* voxels = volume.voxels;
  size_t i = 0;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x)
        out[i++] = voxels->GetScalarComponentAsDouble(int(x), int(y), int(z), 0) == label;
  return CGAL::Image_3(image);
}

struct LabelRange {
  int64_t min = 0;
  int64_t max = 0;
};

// Smallest and largest voxel value; nullopt for a voxel type labelmesh does not keep in memory.
std::optional<LabelRange> label_range(vtkImageData* voxels) {
  LabelRange range;
  if (!volume::visit_voxels(voxels, [&](const auto* v, size_t count) {
        if (count == 0) return;
        const auto [lo, hi] = std::minmax_element(v, v + count);
        range = {int64_t(*lo), int64_t(*hi)};
      }))
    return std::nullopt;
  return range;
}

// The voxel values as unsigned `Word`s (labels in range checked by the caller), placed in
// physical space. VTK and Image_3 both store x fastest, so the voxels copy in order.
template <typename Word>
CGAL::Image_3 labelled_image(const volume::LabelVolume& volume) {
  const auto& g = volume.geometry;
  _image* image = _createImage(g.dims[0], g.dims[1], g.dims[2], 1, g.spacing[0], g.spacing[1],
                               g.spacing[2], sizeof(Word), WK_FIXED, SGN_UNSIGNED);
  image->tx = float(g.origin[0]);
  image->ty = float(g.origin[1]);
  image->tz = float(g.origin[2]);
  auto* out = static_cast<Word*>(image->data);
  volume::visit_voxels(volume.voxels, [&](const auto* v, size_t count) {
    std::transform(v, v + count, out, [](auto label) { return static_cast<Word>(label); });
  });
  return CGAL::Image_3(image);
}

// Mutes std::cout while alive: CGAL's seeding reports progress there, and stdout carries the
// bench report.
class MutedStdout {
 public:
  MutedStdout() : saved_(std::cout.rdbuf(nullptr)) {}
  ~MutedStdout() { std::cout.rdbuf(saved_); }
  MutedStdout(const MutedStdout&) = delete;
  MutedStdout& operator=(const MutedStdout&) = delete;

 private:
  std::streambuf* saved_;
};

// Seeds every connected component of every label, then refines, perturbs and exudes, as CGAL's
// mesh_3D_image_with_custom_initialization example. `Word` is the image's voxel type.
template <typename Word>
void seed_and_refine(Complex& complex, const Domain& domain, const CGAL::Image_3& image,
                     const Criteria& criteria) {
  {
    MutedStdout muted;
    initialize_triangulation_from_labeled_image(complex, domain, image, criteria, Word());
  }
  CGAL::refine_mesh_3(complex, domain, criteria, CGAL::parameters::perturb(),
                      CGAL::parameters::exude());
}

}  // namespace

absl::StatusOr<Mesh3Figures> mesh_label_with_mesh3(const volume::LabelVolume& volume,
                                                   int32_t label) {
  const auto& d = volume.geometry.direction;
  if (d != std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1})
    return absl::UnimplementedError("mesh3 baseline: only axis-aligned volumes");
  CGAL::Image_3 image = binary_image(volume, label);
  namespace params = CGAL::parameters;
  const Domain domain = Domain::create_labeled_image_mesh_domain(image);
  const Criteria criteria(params::facet_angle = 30, params::facet_size = 2,
                          params::facet_distance = 0.5, params::cell_radius_edge_ratio = 3,
                          params::cell_size = 3);
  const auto start = std::chrono::steady_clock::now();
  const Complex complex = CGAL::make_mesh_3<Complex>(domain, criteria);
  Mesh3Figures figures;
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& tr = complex.triangulation();
  for (auto c = complex.cells_in_complex_begin(); c != complex.cells_in_complex_end(); ++c) {
    quality::Tet tet;
    for (int k = 0; k < 4; ++k) {
      const auto p = tr.point(c, k);
      tet[k] = {p.x(), p.y(), p.z()};
    }
    figures.quality.add(quality::tetra_quality(tet));
    figures.quality.add_dihedral_range(quality::tetra_dihedral_range_deg(tet));
  }
  figures.tetrahedra = complex.number_of_cells_in_complex();
  figures.nodes = tr.number_of_vertices();
  return figures;
}

absl::StatusOr<Mesh3LabelsFigures> mesh_labels_with_mesh3(const volume::LabelVolume& volume,
                                                          const Mesh3Sizing& sizing) {
  // Meshed along the image's own axes: volumes and angles do not depend on
  // how the axes are turned in patient space.
  if (!volume.more_layers.empty())
    return absl::UnimplementedError("mesh3 baseline: overlapping label layers");
  if (volume.voxels == nullptr ||
      volume.voxels->GetNumberOfPoints() != volume.geometry.voxel_count())
    return absl::InvalidArgumentError("mesh3 baseline: voxels do not match the geometry");
  const std::optional<LabelRange> range = label_range(volume.voxels);
  if (!range) return absl::InvalidArgumentError("mesh3 baseline: unsupported voxel type");
  if (range->min < 0 || range->max > 65535)
    return absl::UnimplementedError("mesh3 baseline: only labels in [0, 65535]");
  if (range->max == 0) return absl::InvalidArgumentError("mesh3 baseline: no non-zero label");
  const bool labels_fit_a_byte = range->max <= 255;
  const CGAL::Image_3 image =
      labels_fit_a_byte ? labelled_image<uint8_t>(volume) : labelled_image<uint16_t>(volume);
  namespace params = CGAL::parameters;
  const Domain domain = Domain::create_labeled_image_mesh_domain(image);
  const Criteria criteria(params::facet_angle = 30, params::facet_size = sizing.facet_size_mm,
                          params::facet_distance = sizing.facet_distance_mm,
                          params::cell_radius_edge_ratio = 3,
                          params::cell_size = sizing.cell_size_mm);
  // Seeding directions and perturbation draw from the default generator.
  CGAL::get_default_random() = CGAL::Random(0);
  Complex complex;
  const auto start = std::chrono::steady_clock::now();
  if (labels_fit_a_byte)
    seed_and_refine<uint8_t>(complex, domain, image, criteria);
  else
    seed_and_refine<uint16_t>(complex, domain, image, criteria);
  Mesh3LabelsFigures figures;
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& tr = complex.triangulation();
  std::map<int32_t, Mesh3LabelVolume> by_label;
  for (auto c = complex.cells_in_complex_begin(); c != complex.cells_in_complex_end(); ++c) {
    quality::Tet tet;
    for (int k = 0; k < 4; ++k) {
      const auto p = tr.point(c, k);
      tet[k] = {p.x(), p.y(), p.z()};
    }
    figures.quality.add(quality::tetra_quality(tet));
    figures.quality.add_dihedral_range(quality::tetra_dihedral_range_deg(tet));
    const int32_t label = complex.subdomain_index(c);
    Mesh3LabelVolume& entry = by_label[label];
    entry.label = label;
    entry.volume_mm3 += quality::tetra_signed_volume(tet);
    ++entry.tetrahedra;
  }
  for (const auto& [label, entry] : by_label) figures.labels.push_back(entry);
  figures.tetrahedra = complex.number_of_cells_in_complex();
  figures.nodes = tr.number_of_vertices();
  return figures;
}

}  // namespace labelmesh::bench
