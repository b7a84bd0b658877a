// SPDX-License-Identifier: AGPL-3.0-or-later
// Poisson surface reconstruction (paper §2.3, CGAL): a smooth closed surface
// from oriented points, meshed by Delaunay refinement with a minimum angle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/job/poisson_params.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/util/vec3.h"

namespace labelmesh::surface {

struct PoissonParams {
  // Surface mesher criteria (CGAL Surface_mesh_default_criteria_3).
  double min_angle_deg = 30;
  // Upper bound on triangle edges: the surface Delaunay ball radius is bounded
  // by half of it, and a triangle's edges never exceed twice that radius.
  double max_edge_mm = 0;
  // Bound on the distance between a triangle's circumcentre and the centre of
  // its surface Delaunay ball: how far the mesh may stray from the function's
  // zero level.
  double max_distance_mm = 0;
  // The mesher starts from points of the surface this far apart (about a
  // final edge) rather than from a few along rays; 0: CGAL's 20 ray points.
  double seed_spacing_mm = 0;
  PointReduction reduction = PointReduction::kGrid;
  double reduction_cell_mm = 0;
  uint32_t cluster_size = 3;
  // Grid reduction only: when the grid of `reduction_cell_mm` keeps more than
  // this many points, the cell grows by the square root of the excess (points
  // on a surface go as one over the cell's area), in up to ten steps, until
  // no more than this many remain. 0: no budget.
  uint64_t max_points = 0;
  // More points than this (after reduction) are solved as two halves at once,
  // split at their median along the longest side of their box, each reaching
  // `split_overlap_mm` past the split; the two functions are blended across
  // the middle of the overlap. 0: always one solve. The result depends only
  // on the points, not on the machine's cores.
  uint64_t split_points = 0;
  double split_overlap_mm = 0;
  // Relative residual at which the conjugate gradient solve stops.
  double solver_tolerance = 1e-6;
};

struct PoissonFigures {
  size_t input_points = 0;
  size_t used_points = 0;
  // Grid reduction: the cell used, after any growth for the point budget.
  double point_cell_mm = 0;
  // The points were solved as two halves (split_points).
  bool solved_in_halves = false;
  int solver_iterations = 0;
  double solve_seconds = 0;  // Delaunay refinement + linear solve
  double mesh_seconds = 0;   // surface meshing of the zero level
};

// Reconstructs one closed surface from `points` with unit `normals` (zero
// normals are skipped). The result is outward and 2-manifold (CGAL's
// Manifold_tag); the same input always gives the same mesh.
// Errors: INVALID_ARGUMENT for bad parameters or too few points, INTERNAL when
// the solve fails or meshing finds no surface, CANCELLED.
// The surface mesher uses one core: `beside_meshing`, if given, runs on a
// second thread meanwhile (and not at all when the run ends before meshing).
absl::StatusOr<TriangleMesh> reconstruct_poisson_surface(
    const std::vector<geometry::Vec3>& points, const std::vector<geometry::Vec3>& normals,
    const PoissonParams& params, const RunContext& context, PoissonFigures& figures,
    const std::function<void()>& beside_meshing = {});

}  // namespace labelmesh::surface
