// SPDX-License-Identifier: AGPL-3.0-or-later
// Lifting the tetrahedra the improvement pass cannot reach: those whose
// corners all lie on interfaces, which it never moves. Each interface point
// of such a tetrahedron slides in its interface's tangent plane to where the
// worst tetrahedron around it is best (a pattern search), so every interface
// stays where it was to first order and no face changes sides.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/util/run_context.h"
#include "core/volume_mesh/tet_mesh.h"

namespace labelmesh::conforming {

struct SlideParams {
  // Tetrahedra below either bound are worked on.
  double target_quality = 0.3;
  double target_dihedral_deg = 15;
  int max_sweeps = 4;
  // Steps off the interface, as a fraction of the steps along it: 0 keeps
  // every interface where it was to first order; above 0 lets a point leave
  // it too (still within its reach), which lifts slivers whose corners lie
  // on one flat patch.
  double off_fraction = 0;
};

struct SlideFigures {
  size_t points_moved = 0;
  size_t tetrahedra_below_before = 0;
  size_t tetrahedra_below_after = 0;
  double seconds = 0;
};

// Slides points [0, interface_points) of `mesh` (the interface surface's
// points, as tetrahedralize_interfaces keeps them): in their interface's
// tangent plane, along their junction curve where three labels meet, and,
// with params.off_fraction > 0, off those too (then also the points where
// curves meet, which otherwise stay). A point never moves farther than
// `reach[p]` mm from `anchor[p]` (the voxels' staircase, so the interfaces
// stay as close to the voxel boundary as they were), no tetrahedron
// inverts, no interface face turns by more than 30 degrees, and a move is
// kept only when it raises the worst tetrahedron around the point.
// Errors: CANCELLED.
absl::Status slide_interface_points(volume_mesh::TetMesh& mesh, size_t interface_points,
                                    const std::vector<std::array<double, 3>>& anchor,
                                    const std::vector<double>& reach, const SlideParams& params,
                                    const RunContext& context, SlideFigures& figures);

}  // namespace labelmesh::conforming
