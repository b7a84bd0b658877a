// SPDX-License-Identifier: AGPL-3.0-or-later
// What a TetGen run is asked for, and the ranges TetGen accepts: no TetGen
// here, so that job options are checked where TetGen is not linked.
#pragma once

#include "absl/status/status.h"

namespace labelmesh::volume_mesh {

// What the user asks of the mesh. Ranges are checked by check_tetgen_params
// (the job options and every TetGen run call it).
struct TetgenParams {
  // Upper bound on each tetrahedron's circumradius / shortest edge (TetGen -q), dimensionless, in
  // [1, 100]. TetGen may not terminate below 1; a regular tetrahedron has 0.612.
  double radius_edge_ratio = 1.414;
  // Lower bound on each tetrahedron's dihedral angles (the second -q value), in degrees, in
  // [0, 30]; 0 leaves angles unbounded.
  double min_dihedral_deg = 10;
  // Upper bound on each tetrahedron's volume (TetGen -a), in mm³; 0 for no bound, otherwise in
  // [1e-6, 1e12].
  double max_volume_mm3 = 0;
  // Keep the boundary triangles as given (TetGen -Y): no Steiner points on the surface, so the
  // mesh's boundary faces are exactly the input triangles. Refinement then happens inside only.
  // (Labels meshed from their own surfaces still do not share nodes where they touch.)
  bool keep_boundary = true;
  // Target of TetGen's own optimisation (-o/, edge and face flips and vertex smoothing after
  // refinement): tetrahedra with a larger dihedral angle are worked on. TetGen's default, 165,
  // leaves the liver's worst elements (166°) alone; 140 lifts its lowest Q from 0.10 to 0.17.
  // In [90, 179].
  double max_dihedral_deg = 140;
};

// INVALID_ARGUMENT naming the job option (tet_radius_edge, ...) when a
// parameter is out of TetGen's range.
absl::Status check_tetgen_params(const TetgenParams& params);

}  // namespace labelmesh::volume_mesh
