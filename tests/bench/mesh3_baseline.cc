// SPDX-License-Identifier: AGPL-3.0-or-later
// The only translation unit that instantiates Mesh_3 (slow to compile).
#include "bench/mesh3_baseline.h"

#include <chrono>
#include <cstring>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/make_mesh_3.h>
#include <vtkImageData.h>

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

}  // namespace labelmesh::bench
