// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_mixed_meshes.h"

#include <algorithm>
#include <chrono>

#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

void add_figures(mixed_mesh::MixedFigures& sum, const mixed_mesh::MixedFigures& part) {
  sum.grid_cells += part.grid_cells;
  sum.depth_queries += part.depth_queries;
  sum.core_cells_removed += part.core_cells_removed;
  sum.core_seconds += part.core_seconds;
  sum.surface_volume_mm3 += part.surface_volume_mm3;
  for (size_t level = 0; level < std::size(sum.octree.octants); ++level)
    sum.octree.octants[level] += part.octree.octants[level];
  sum.octree.balance_splits += part.octree.balance_splits;
  sum.octree.transition_octants += part.octree.transition_octants;
  sum.layer.layer_hexahedra += part.layer.layer_hexahedra;
  sum.layer.split_hexahedra += part.layer.split_hexahedra;
  sum.layer.boundary_distance_max_mm =
      std::max(sum.layer.boundary_distance_max_mm, part.layer.boundary_distance_max_mm);
  sum.tetgen.input_points += part.tetgen.input_points;
  sum.tetgen.input_triangles += part.tetgen.input_triangles;
  sum.tetgen.steiner_points += part.tetgen.steiner_points;
  sum.tetgen.tetrahedra += part.tetgen.tetrahedra;
  sum.tetgen.seconds += part.tetgen.seconds;
}

void add_conformity(mixed_mesh::Conformity& sum, const mixed_mesh::Conformity& part) {
  sum.interior_faces += part.interior_faces;
  sum.boundary_faces += part.boundary_faces;
  sum.nonconforming_faces += part.nonconforming_faces;
  sum.duplicate_points += part.duplicate_points;
  sum.open_boundary_edges += part.open_boundary_edges;
}

}  // namespace

absl::StatusOr<MixedVolumeResult> mesh_labels_mixed(const std::vector<LabelBoundary>& boundaries,
                                                    const mixed_mesh::MixedParams& params,
                                                    const RunContext& context) {
  const auto start = std::chrono::steady_clock::now();
  MixedVolumeResult result;
  result.cell_mm = params.core.cell_mm;
  result.hexahedra_only = params.hexahedra_only;
  result.interior_mm = params.octree.interior_mm;
  for (size_t i = 0; i < boundaries.size(); ++i) {
    const LabelBoundary& boundary = boundaries[i];
    // TetGen's own stage reports count as this stage's, label by label.
    const double count = double(boundaries.size());
    RunContext label_context = context;
    if (context.progress) {
      label_context.progress = [&context, i, count](const ProgressUpdate& update) {
        context.progress({"mixed_mesh", (double(i) + update.fraction) / count, nullptr});
      };
    }
    label_context.report("mixed_mesh", 0);
    LABELMESH_RETURN_IF_ERROR(check_fillable(boundary));
    mixed_mesh::MixedFigures figures;
    auto mesh =
        mixed_mesh::mesh_mixed(*boundary.surface, boundary.label, params, label_context, figures);
    if (!mesh.ok()) {
      if (mesh.status().code() == absl::StatusCode::kCancelled) return mesh.status();
      return absl::Status(mesh.status().code(), cat("label ", boundary.label, ": ",
                                                    std::string(mesh.status().message())));
    }
    if (figures.left_out) {
      result.labels_left_out.push_back({boundary.label, figures.layer_refused});
      continue;
    }
    if (!figures.layer_refused.empty())
      result.tetrahedral_layer_labels.push_back({boundary.label, figures.layer_refused});
    if (auto s = mixed_mesh::check_mixed_mesh(*mesh); !s.ok()) {
      return absl::InternalError(cat("label ", boundary.label, ": ", std::string(s.message())));
    }
    // Per label: labels are meshed apart, and where two touch their
    // surfaces may share points that are rightly two nodes.
    add_conformity(result.conformity, mixed_mesh::check_conformity(*mesh));
    result.mesh.append(*mesh);
    add_figures(result.figures, figures);
  }
  context.report("mixed_mesh", 1);
  result.surface_volume_mm3 = result.figures.surface_volume_mm3;
  result.quality = mixed_mesh::measure_mixed_mesh(result.mesh);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace labelmesh
