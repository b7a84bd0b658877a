// SPDX-License-Identifier: AGPL-3.0-or-later
// The volume stage of the pipeline (paper §2.4): a tetrahedral mesh of every
// label's output surface, with each element's quality (§2.4.1).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/conforming/conforming_mesher.h"
#include "core/quality/element_quality.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/improve_tet_mesh.h"
#include "core/volume_mesh/tet_mesh.h"
#include "core/volume_mesh/tetrahedralize.h"

namespace labelmesh {

struct VolumeImprovement {
  // TetGen's mesh, as it was before the pass.
  quality::QualitySummary tetgen_summary;
  volume_mesh::ImproveFigures figures;
};

struct VolumeResult {
  std::string mesher = "tetgen";
  volume_mesh::TetMesh mesh;
  // Q = 1/A_gamma of each tetrahedron, in mesh order.
  std::vector<double> quality;
  quality::QualitySummary summary;
  size_t steiner_points = 0;
  double seconds = 0;
  // Set when the improvement pass ran.
  std::optional<VolumeImprovement> improvement;
  // Conforming meshes only.
  std::optional<conforming::ConformingFigures> conforming;
  // Files written for it, relative to the output directory.
  std::vector<std::string> files;
};

// Fills `quality` and `summary` from the mesh.
void measure(VolumeResult& result);

// One label's closed, outward surface to fill with tetrahedra.
struct LabelBoundary {
  int32_t label = 0;
  const surface::TriangleMesh* surface = nullptr;
  // Pairs of crossing triangles found by the surface checks, if counted.
  std::optional<uint64_t> self_intersections;
};

// FAILED_PRECONDITION naming the label when the surface checks found its
// triangles crossing: no volume mesher can fill such a surface.
absl::Status check_fillable(const LabelBoundary& boundary);

// Tetrahedralizes each boundary with TetGen and measures every element.
// Errors: FAILED_PRECONDITION naming the label when its surface intersects
// itself or TetGen refuses it; INVALID_ARGUMENT for bad TetGen options or a
// broken surface; RESOURCE_EXHAUSTED; CANCELLED; INTERNAL.
absl::StatusOr<VolumeResult> tetrahedralize_labels(const std::vector<LabelBoundary>& boundaries,
                                                   const volume_mesh::TetgenParams& params,
                                                   const RunContext& context);

// The improvement pass (volume_mesh::improve_tet_mesh) on every label's
// tetrahedra, then the quality figures again. Does nothing when
// params.target_quality is 0. Errors: CANCELLED, RESOURCE_EXHAUSTED.
absl::Status improve_volume(VolumeResult& volume, const volume_mesh::ImproveParams& params,
                            const RunContext& context);

}  // namespace labelmesh
