// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_tet_meshes.h"

#include <chrono>
#include <new>

#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

absl::StatusOr<VolumeResult> measure_and_join(const std::vector<LabelBoundary>& boundaries,
                                              const volume_mesh::TetgenParams& params,
                                              const RunContext& context) {
  const auto start = std::chrono::steady_clock::now();
  VolumeResult result;
  for (const auto& boundary : boundaries) {
    // TetGen's own -d check would say the same, less precisely and later.
    LABELMESH_RETURN_IF_ERROR(check_fillable(boundary));
    volume_mesh::TetgenFigures figures;
    auto tets =
        volume_mesh::tetrahedralize(*boundary.surface, boundary.label, params, context, figures);
    if (!tets.ok()) {
      return absl::Status(tets.status().code(), cat("label ", boundary.label, ": ",
                                                    std::string(tets.status().message())));
    }
    result.steiner_points += figures.steiner_points;
    result.mesh.append(*tets);
  }
  measure(result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace

void measure(VolumeResult& result) {
  result.summary = volume_mesh::summarise_quality(result.mesh, &result.quality);
}

absl::StatusOr<VolumeResult> tetrahedralize_labels(const std::vector<LabelBoundary>& boundaries,
                                                   const volume_mesh::TetgenParams& params,
                                                   const RunContext& context) {
  // No exception leaves the core: a mesh too large for memory is an error.
  try {
    return measure_and_join(boundaries, params, context);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError("tetgen: out of memory joining the volume meshes");
  }
}

absl::Status improve_volume(VolumeResult& volume, const volume_mesh::ImproveParams& params,
                            const RunContext& context) {
  if (params.target_quality <= 0) return absl::OkStatus();
  VolumeImprovement improvement;
  improvement.tetgen_summary = volume.summary;
  try {
    if (auto s = volume_mesh::improve_tet_mesh(volume.mesh, params, context, improvement.figures);
        !s.ok()) {
      return s;
    }
    measure(volume);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError("tet improvement: out of memory");
  }
  volume.improvement = improvement;
  return absl::OkStatus();
}

absl::Status check_fillable(const LabelBoundary& boundary) {
  if (boundary.self_intersections.value_or(0) == 0) return absl::OkStatus();
  return absl::FailedPreconditionError(
      cat("label ", boundary.label, ": its surface has ", *boundary.self_intersections,
          " pairs of crossing triangles; a volume mesh needs a surface that does not "
          "intersect itself"));
}

}  // namespace labelmesh
