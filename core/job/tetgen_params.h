// SPDX-License-Identifier: AGPL-3.0-or-later
// What a TetGen run and the improvement pass after it are asked for, and the
// ranges TetGen accepts: no TetGen here, so that job options are checked
// where TetGen is not linked.
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

// The improvement pass after TetGen (volume_mesh/improve_tet_mesh.h).
struct ImproveParams {
  // Tetrahedra with Q below this are worked on; the rest only take part as
  // neighbours. Above the Table 1 "questionable" bound of 0.2, so the pass
  // also lifts elements that are just good enough.
  double target_quality = 0.3;
  // Tetrahedra whose smallest dihedral angle is below this (degrees, 0 to
  // 60) are worked on too: each counts as the lower of its Q and
  // target_quality times its smallest dihedral over this. 0: Q alone.
  double target_dihedral_deg = 0;
  // Full sweeps over the bad tetrahedra; a sweep that changes nothing ends
  // the pass early.
  int max_sweeps = 8;
  // No operation makes a tetrahedron larger than this (mm³) and larger than
  // those it replaces; 0 for no bound. The pipeline passes TetGen's -a bound.
  double max_volume_mm3 = 0;
  // How far (mm) peeling a sliver off the surface may move it; 0 turns
  // peeling off. The pipeline passes the Poisson surface's distance bound
  // for Poisson surfaces and 0 for the others.
  double max_peel_depth_mm = 0;
};

}  // namespace labelmesh::volume_mesh
