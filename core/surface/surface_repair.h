// SPDX-License-Identifier: AGPL-3.0-or-later
// Repair of a Marching Cubes surface (paper §2.2, "MC improved" in Table 2),
// with CGAL Polygon_mesh_processing: the result is a closed, outward,
// 2-manifold surface without degenerate or sharp triangles.
#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"

namespace labelmesh::surface {

struct RepairParams {
  // A triangle whose longest edge is at least this many times its shortest
  // is a needle: its shortest edge is collapsed.
  double needle_ratio = 4;
  // A triangle with an angle of at least this many degrees is a cap: its
  // longest edge is flipped or collapsed.
  double cap_angle_deg = 160;
  // Edges longer than this are never collapsed (mm): bounds how far a repair
  // can move the surface. The pipeline passes one voxel.
  double max_collapse_length_mm = 1;
};

// What the repair changed, for the report.
struct RepairCounts {
  // Triangles with repeated or collinear corners, removed.
  uint32_t degenerate_triangles_removed = 0;
  // Needles and caps before and after the collapse pass.
  uint32_t needles_before = 0;
  uint32_t caps_before = 0;
  uint32_t needles_after = 0;
  uint32_t caps_after = 0;
  // Vertices shared by separate fans, given one copy per fan.
  uint32_t non_manifold_vertices_split = 0;
  // Boundary cycles closed by hole triangulation.
  uint32_t holes_filled = 0;
};

// Repairs `mesh`: soup cleanup (duplicate points, repeated corners), split of
// non-manifold vertices, consistent orientation, degenerate triangles, needles
// and caps, hole filling, then outward orientation. Points not involved in a
// defect keep their exact coordinates.
// Errors: INTERNAL when CGAL cannot build a mesh from the soup, CANCELLED.
absl::StatusOr<TriangleMesh> repair_surface(const TriangleMesh& mesh, const RepairParams& params,
                                            const RunContext& context, RepairCounts& counts);

}  // namespace labelmesh::surface
