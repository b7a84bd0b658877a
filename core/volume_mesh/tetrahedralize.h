// SPDX-License-Identifier: AGPL-3.0-or-later
// Quality tetrahedral meshes of the region a closed surface encloses, with TetGen 1.5: a
// constrained Delaunay tetrahedralization refined by Shewchuk's Delaunay refinement. Reference:
// H. Si, "TetGen: A Quality Tetrahedral Mesh Generator and a 3D Delaunay Triangulator,
// Version 1.5 User's Manual", WIAS Technical Report 13 (2013), §4.2 (switches -p -q -a -Y -d).
// TetGen is included only in tetrahedralize.cc, so its licence and compile cost stay there.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/job/tetgen_params.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/tet_mesh.h"

namespace labelmesh::volume_mesh {

// Figures of one run, for the report.
struct TetgenFigures {
  size_t input_points = 0;     // surface points passed to TetGen (those triangles use)
  size_t input_triangles = 0;  // surface triangles passed to TetGen
  size_t steiner_points = 0;   // points TetGen added: mesh points minus input points
  size_t tetrahedra = 0;       // tetrahedra in the result
  double seconds = 0;          // wall time of the whole call
};

// Meshes the region inside `boundary` with tetrahedra labelled `label`.
//
// `boundary` must be closed and wound outwards (normals point out of the material). It may have
// several components: separate bodies, and nested shells, where an inner shell wound inwards
// (towards its own inside) bounds a cavity that stays empty. Points no triangle uses are ignored.
// TetGen cannot be interrupted: `context` is polled before and after each TetGen run, and
// progress is reported at the same points. Figures are filled as far as the run got.
//
// Result: points in LPS mm, only those some tetrahedron uses (input points keep their exact
// coordinates); tetrahedra in VTK ordering (positive volume, checked); every label `label`.
// With keep_boundary the quality and volume bounds hold only where TetGen can refine without
// touching the surface: next to coarse triangles (whose diametral balls cover the interior)
// tetrahedra may exceed them, and TetGen's optimisation (-o/) may merge tetrahedra a few percent
// past the -a bound, so the bounds are targets to report against, not guarantees.
//
// Errors:
// - INVALID_ARGUMENT: a parameter out of range (the message names the option, e.g.
//   "tet_radius_edge: ..."); a boundary with fewer than 4 points or 4 triangles, a triangle
//   naming a missing point, or a triangle with a repeated corner.
// - FAILED_PRECONDITION: the surface intersects itself (found by TetGen's -d check), is wound
//   inwards, or TetGen rejects it (a feature below its tolerance, nearly coincident facets).
// - RESOURCE_EXHAUSTED: TetGen ran out of memory.
// - CANCELLED: a stop was requested.
// - INTERNAL: TetGen reported an internal error, or produced a tetrahedron without positive
//   volume.
//
// Debian's TetGen 1.5.0 frees its memory twice when it fails (terminatetetgen() frees it, then
// the unwinding destructor of its mesh frees it again), which crashes the process rather than
// throwing. Self-intersection, the common failure, is therefore detected up front with -d, which
// reports instead of failing; for the rest, the server runs jobs in child processes.
absl::StatusOr<TetMesh> tetrahedralize(const surface::TriangleMesh& boundary, int32_t label,
                                       const TetgenParams& params, const RunContext& context,
                                       TetgenFigures& figures);

// tetrahedralize() when the caller knows the cavities: `holes` (non-null)
// holds a point inside each, and TetGen carves them out without the extra
// run that finds them.
absl::StatusOr<TetMesh> tetrahedralize_around(const surface::TriangleMesh& boundary, int32_t label,
                                              const TetgenParams& params,
                                              const std::vector<std::array<double, 3>>* holes,
                                              const RunContext& context, TetgenFigures& figures);

}  // namespace labelmesh::volume_mesh
