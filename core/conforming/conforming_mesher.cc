// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/conforming_mesher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>

#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"

namespace labelmesh::conforming {
namespace {

// Voxels per selected label (every non-zero label when `labels` is empty).
std::vector<std::pair<int32_t, uint64_t>> voxel_counts(const volume::LabelVolume& volume,
                                                       const std::vector<int32_t>& labels) {
  std::vector<std::pair<int32_t, uint64_t>> selected;
  for (const auto& label : volume::compute_label_statistics(volume).labels) {
    if (labels.empty() || std::find(labels.begin(), labels.end(), label.label) != labels.end())
      selected.push_back({label.label, label.voxels});
  }
  return selected;
}

// Puts the points of crossing triangles back on the staircase until nothing
// crosses; after the last round, every point.
absl::Status remove_crossings(InterfaceSurface& surface, int max_rounds, const RunContext& context,
                              ConformingFigures& figures) {
  for (int round = 0;; ++round) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    LABELMESH_ASSIGN_OR_RETURN(auto crossing, crossing_points(surface));
    if (crossing.empty()) return absl::OkStatus();
    if (round == max_rounds) {
      std::vector<uint32_t> all(surface.points.size());
      for (uint32_t p = 0; p < all.size(); ++p) all[p] = p;
      restore_staircase(surface, all);
      figures.staircase_only = true;
      return absl::OkStatus();
    }
    ++figures.crossing_repairs;
    figures.restored_points += crossing.size();
    restore_staircase(surface, crossing);
  }
}

// The interfaces on the grid they are made on: the input's, coarsened when
// its interfaces would be too large, with thick slices cut thinner. The
// voxels counted for each label stay the measure of its volume. `spacing`
// gets that grid's spacing.
absl::StatusOr<InterfaceSurface> grid_interfaces(const volume::LabelVolume& volume,
                                                 const std::vector<int32_t>& labels,
                                                 const ConformingParams& params,
                                                 const RunContext& context,
                                                 ConformingFigures& figures,
                                                 std::array<double, 3>& spacing) {
  const auto start = std::chrono::steady_clock::now();
  figures.coarsening = choose_coarsening(volume, labels, params.max_interface_faces);
  std::optional<volume::LabelVolume> coarse, thinner;
  const volume::LabelVolume* grid = &volume;
  if (figures.coarsening.factors != std::array<double, 3>{1, 1, 1}) {
    LABELMESH_ASSIGN_OR_RETURN(auto coarsened,
                               coarsen_labels(volume, labels, figures.coarsening.factors, context));
    coarse = std::move(coarsened);
    grid = &*coarse;
  }
  figures.thick_slices = find_thick_slices(grid->geometry, params.thick_slices);
  if (figures.thick_slices.axis >= 0) {
    LABELMESH_ASSIGN_OR_RETURN(
        auto cut, interpolate_thick_slices(*grid, labels, figures.thick_slices, context));
    thinner = std::move(cut);
    grid = &*thinner;
    coarse.reset();
  }
  figures.grid_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spacing = grid->geometry.spacing;
  return label_interfaces(*grid, labels, params.interfaces, figures.interfaces);
}

}  // namespace

double LabelVolumeFigures::volume_change() const {
  return voxel_volume_mm3 > 0 ? (mesh_volume_mm3 - voxel_volume_mm3) / voxel_volume_mm3 : 0;
}

VolumeChangeSpread volume_change_spread(const std::vector<LabelVolumeFigures>& labels,
                                        uint64_t min_voxels) {
  std::vector<double> changes;
  for (const auto& label : labels) {
    if (label.voxels >= min_voxels) changes.push_back(std::abs(label.volume_change()));
  }
  if (changes.empty()) return {};
  std::sort(changes.begin(), changes.end());
  const auto at = [&](double q) {
    return changes[static_cast<size_t>(std::lround(q * double(changes.size() - 1)))];
  };
  return {at(0.5), at(0.9), changes.back(), changes.size()};
}

std::vector<LabelVolumeFigures> label_volume_figures(
    const volume_mesh::TetMesh& mesh, const std::vector<std::pair<int32_t, uint64_t>>& voxels,
    double voxel_volume_mm3) {
  std::vector<LabelVolumeFigures> figures;
  std::map<int32_t, size_t> at;
  for (const auto& [label, count] : voxels) {
    at[label] = figures.size();
    figures.push_back({label, count, static_cast<double>(count) * voxel_volume_mm3, 0, 0});
  }
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const auto it = at.find(mesh.labels[t]);
    if (it == at.end()) continue;
    figures[it->second].mesh_volume_mm3 += volume_mesh::signed_volume(mesh, t);
    ++figures[it->second].tetrahedra;
  }
  return figures;
}

absl::StatusOr<volume_mesh::TetMesh> mesh_conforming(const volume::LabelVolume& volume,
                                                     const std::vector<int32_t>& labels,
                                                     const ConformingParams& params,
                                                     const RunContext& context,
                                                     ConformingFigures& figures,
                                                     volume_mesh::ImproveFigures& improve) {
  const auto start = std::chrono::steady_clock::now();
  figures = ConformingFigures{};
  LABELMESH_RETURN_IF_ERROR(volume_mesh::check_tetgen_params(params.tetgen));
  const auto voxels = voxel_counts(volume, labels);
  if (voxels.empty()) {
    return absl::InvalidArgumentError(
        "conforming mesh: no voxel holds any of the selected labels; nothing to mesh");
  }
  context.report("interfaces", 0);
  std::array<double, 3> spacing{};
  LABELMESH_ASSIGN_OR_RETURN(auto interfaces,
                             grid_interfaces(volume, labels, params, context, figures, spacing));
  InterfaceSurface surface = std::move(interfaces);
  if (auto status = remove_crossings(surface, params.max_crossing_repairs, context, figures);
      !status.ok()) {
    return status;
  }
  auto mesh =
      tetrahedralize_interfaces(surface, params.tetgen, context, figures.tetgen, figures.regions);
  if (!mesh.ok()) return mesh.status();
  figures.tetgen_quality = volume_mesh::summarise_quality(*mesh);
  std::vector<double> reach(surface.points.size());
  const double least_reach =
      params.slide_reach_voxels * std::min({spacing[0], spacing[1], spacing[2]});
  for (size_t p = 0; p < reach.size(); ++p) {
    reach[p] = std::max(least_reach,
                        geometry::norm(geometry::sub(surface.points[p], surface.staircase[p])));
  }
  context.report("tet_improve", 0);
  SlideFigures slid;
  if (auto status = slide_interface_points(*mesh, surface.points.size(), surface.staircase, reach,
                                           params.slide, context, slid);
      !status.ok()) {
    return status;
  }
  figures.slide = slid;
  if (params.improve.target_quality > 0) {
    // Inside the labels the pass lifts what the slides aim for on the
    // interfaces: tetrahedra whose corners are not all on them.
    volume_mesh::ImproveParams inside = params.improve;
    inside.target_dihedral_deg =
        std::max(inside.target_dihedral_deg, params.slide.target_dihedral_deg);
    if (auto status = volume_mesh::improve_tet_mesh(*mesh, inside, context, improve);
        !status.ok()) {
      return status;
    }
  }
  // The improvement pass keeps the points it does not drop in order, and it
  // never drops interface points, which it does not touch. The last slide
  // may also step off the interfaces, within the same reach.
  SlideParams last_slide = params.slide;
  last_slide.off_fraction = params.last_slide_off_fraction;
  if (auto status = slide_interface_points(*mesh, surface.points.size(), surface.staircase, reach,
                                           last_slide, context, slid);
      !status.ok()) {
    return status;
  }
  figures.slide.points_moved += slid.points_moved;
  figures.slide.tetrahedra_below_after = slid.tetrahedra_below_after;
  figures.slide.seconds += slid.seconds;
  figures.interfaces.max_offset_mm = 0;
  for (size_t p = 0; p < surface.points.size(); ++p) {
    figures.interfaces.max_offset_mm =
        std::max(figures.interfaces.max_offset_mm,
                 geometry::norm(geometry::sub(mesh->points[p], surface.staircase[p])));
  }
  figures.conformity = check_conforming_mesh(*mesh);
  figures.labels = label_volume_figures(*mesh, voxels, volume.geometry.voxel_volume());
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!figures.conformity.ok()) {
    return absl::FailedPreconditionError(
        cat("conforming mesh: failed its conformity check: ", figures.conformity.failures()));
  }
  return mesh;
}

}  // namespace labelmesh::conforming
