// SPDX-License-Identifier: AGPL-3.0-or-later
// Mesh improvement after TetGen: local operations that raise the
// worst tetrahedron quality Q without touching the boundary.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/job/tetgen_params.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/tet_mesh.h"

namespace labelmesh::volume_mesh {

struct ImproveFigures {
  double quality_min_before = 0;
  double quality_min_after = 0;
  size_t flips_2_3 = 0;          // face shared by two tetrahedra replaced by an edge and three
  size_t flips_3_2 = 0;          // edge with three tetrahedra around it removed, leaving two
  size_t vertices_moved = 0;     // accepted smoothing moves of interior vertices
  size_t vertices_inserted = 0;  // points added inside a bad tetrahedron's neighbourhood
  size_t slivers_peeled = 0;     // questionable slivers with two surface faces removed
  double peeled_volume_mm3 = 0;  // the volume they held
  double peel_depth_mm = 0;      // the deepest of them: how far the surface moved
  int sweeps = 0;
  double seconds = 0;
};

// Improves `mesh` in place. Points on boundary faces (faces only one
// tetrahedron has) never move, and no tetrahedron changes label: flips and
// insertions only replace tetrahedra of one label inside the region they
// fill, and smoothing moves only points no boundary face uses. Every
// operation is kept only if it raises the lowest score among the tetrahedra
// it replaces, so the worst element never gets worse, and none becomes
// inverted. The score is Q, or with params.target_dihedral_deg the lower of
// Q and target_quality times the smallest dihedral over that target: then
// a tetrahedron's Q may fall, but never below the lowest score before.
//
// The one exception to a fixed boundary is peeling: a questionable sliver
// (Q <= 0.2) that nothing else lifts, whose two outer surface faces fold over
// an edge, is removed when it is no thicker than `max_peel_depth_mm` and
// shares no point with a sliver peeled before. The surface then runs over its
// other two faces, through the same points, and moves nowhere further than
// that depth.
//
// Existing points keep their order (inserted points are appended), except
// that a point no tetrahedron uses any more (an insertion's cavity held its
// whole star) is dropped; tetrahedra are renumbered.
// Precondition: check_tet_mesh(mesh) is OK and every tetrahedron has positive
// volume. Errors: CANCELLED when `context` asks to stop (the mesh is then
// valid, partly improved).
absl::Status improve_tet_mesh(TetMesh& mesh, const ImproveParams& params, const RunContext& context,
                              ImproveFigures& figures);

}  // namespace labelmesh::volume_mesh
