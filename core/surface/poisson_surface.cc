// SPDX-License-Identifier: AGPL-3.0-or-later
// The only translation unit that instantiates CGAL's Poisson reconstruction and
// surface mesher: it is slow to compile, so nothing else includes these headers.
#include "core/surface/poisson_surface.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>

#include <CGAL/Poisson_reconstruction_function.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/grid_simplify_point_set.h>
#include <CGAL/hierarchy_simplify_point_set.h>
#include <CGAL/make_surface_mesh.h>
#include <CGAL/property_map.h>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/surface/cgal/restricted_delaunay.h"
#include "core/surface/poisson/hinted_poisson_evaluator.h"
#include "core/surface/poisson/mesher_seeds.h"
#include "core/surface/poisson/poisson_linear_system.h"
#include "core/surface/poisson/zero_level_oracle.h"
#include "core/util/exception_status.h"
#include "core/util/side_by_side.h"
#include "core/util/stage_timer.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::surface {
namespace {

using cgal::Kernel;
using cgal::Point;
using Vector = Kernel::Vector_3;
using OrientedPoint = std::pair<Point, Vector>;
using PointMap = CGAL::First_of_pair_property_map<OrientedPoint>;
using NormalMap = CGAL::Second_of_pair_property_map<OrientedPoint>;
using poisson::CancellableSolver;
using poisson::Cancelled;
using poisson::HintedEvaluator;
using poisson::PoissonFunction;
using poisson::SolvedFunction;
using poisson::ZeroLevel;
using poisson::ZeroLevelOracle;
using restricted_delaunay::Complex;
using restricted_delaunay::complex_to_mesh;
using restricted_delaunay::Triangulation;

// CGAL calls this before inserting each input point into its triangulation.
struct CancellableInsertion {
  const RunContext* context;
  void before_insertion() const {
    if (context->stop_requested()) throw Cancelled{};
  }
};

}  // namespace
}  // namespace labelmesh::surface

// CGAL's constructor from oriented points, as solve() below calls it, but
// without the points' average spacing, which CGAL computes (a search for each
// point's 6 nearest neighbours, costly on large surfaces) only for an
// extra refinement pass that compute_implicit_function makes when given an
// approximation ratio, and solve() gives none.
template <>
template <>
CGAL::Poisson_reconstruction_function<labelmesh::surface::poisson::StopAwareKernel>::
    Poisson_reconstruction_function(
        std::vector<labelmesh::surface::OrientedPoint>::const_iterator first,
        std::vector<labelmesh::surface::OrientedPoint>::const_iterator beyond,
        labelmesh::surface::PointMap point_map, labelmesh::surface::NormalMap normal_map,
        labelmesh::surface::CancellableInsertion visitor)
    : m_tr(new Triangulation), m_bary(new std::vector<Cached_bary_coord>), average_spacing(0) {
  forward_constructor(first, beyond, point_map, normal_map, visitor);
}

namespace labelmesh::surface {
namespace {

absl::Status check_params(const PoissonParams& params) {
  if (!(params.min_angle_deg > 0 && params.min_angle_deg <= 30)) {
    return absl::InvalidArgumentError(
        cat("min-angle: ", params.min_angle_deg, " is outside (0, 30] degrees"));
  }
  if (!(params.max_edge_mm > 0) || !std::isfinite(params.max_edge_mm))
    return absl::InvalidArgumentError("max-edge: must be a positive length");
  if (!(params.max_distance_mm > 0) || !std::isfinite(params.max_distance_mm))
    return absl::InvalidArgumentError("max-distance: must be a positive length");
  if (params.reduction == PointReduction::kGrid &&
      (!(params.reduction_cell_mm > 0) || !std::isfinite(params.reduction_cell_mm)))
    return absl::InvalidArgumentError("point-cell: must be a positive length");
  LABELMESH_RETURN_IF_ERROR(check_point_count("max-points", params.max_points));
  LABELMESH_RETURN_IF_ERROR(check_point_count("split-points", params.split_points));
  if (params.split_points != 0 &&
      (!(params.split_overlap_mm > 0) || !std::isfinite(params.split_overlap_mm)))
    return absl::InvalidArgumentError("split overlap: must be a positive length");
  if (params.reduction == PointReduction::kHierarchy &&
      !(params.cluster_size >= 1 && params.cluster_size <= kMaxClusterSize))
    return absl::InvalidArgumentError(
        cat("point-cluster-size: ", params.cluster_size, " is outside 1..", kMaxClusterSize));
  return absl::OkStatus();
}

std::vector<OrientedPoint> grid_simplified(std::vector<OrientedPoint> points, double cell) {
  points.erase(CGAL::grid_simplify_point_set(points, cell, CGAL::parameters::point_map(PointMap())),
               points.end());
  return points;
}

void reduce_points(std::vector<OrientedPoint>& points, const PoissonParams& params,
                   PoissonFigures& figures) {
  switch (params.reduction) {
    case PointReduction::kNone:
      return;
    case PointReduction::kGrid: {
      double cell = params.reduction_cell_mm;
      auto kept = grid_simplified(points, cell);
      // The square-root rule undershoots (the liver: 139 k points after one
      // step for a budget of 125 k), so it steps again, from the unthinned
      // points, growing at least 2 % a step: ten steps reach the budget
      // unless the cell started far below the points' spacing.
      for (int step = 0; step < 10 && params.max_points != 0 && kept.size() > params.max_points;
           ++step) {
        cell *= std::max(std::sqrt(double(kept.size()) / double(params.max_points)), 1.02);
        kept = grid_simplified(points, cell);
      }
      figures.point_cell_mm = cell;
      points = std::move(kept);
      return;
    }
    case PointReduction::kHierarchy:
      // CGAL's variation bound stays at its default: any 3 points are
      // coplanar, so at the sizes worth using the size decides.
      points.erase(CGAL::hierarchy_simplify_point_set(
                       points, CGAL::parameters::point_map(PointMap()).size(params.cluster_size)),
                   points.end());
      return;
  }
}

struct Solve {
  std::unique_ptr<PoissonFunction> function;
  int iterations = 0;
  bool converged = false;
};

Solve solve(const std::vector<OrientedPoint>& points, const PoissonParams& params,
            const RunContext& context) {
  // CGAL's refinement and assembly poll this thread's run for a stop.
  const poisson::SolveScope scope(context);
  Solve result;
  result.function = std::make_unique<PoissonFunction>(points.begin(), points.end(), PointMap(),
                                                      NormalMap(), CancellableInsertion{&context});
  CancellableSolver solver(&context, params.solver_tolerance, &result.iterations);
  result.converged =
      result.function->compute_implicit_function(solver, CancellableInsertion{&context});
  return result;
}

// Two overlapping halves of the points, split at their median along the
// longest side of their box.
struct Halves {
  int axis = 0;
  double at = 0;
  std::vector<OrientedPoint> low, high;
  // Points strictly below the split: few when many share one plane there.
  size_t below = 0;
  // The box of all the points.
  std::array<double, 3> low_corner{}, high_corner{};
};

Halves split_points(const std::vector<OrientedPoint>& points, double overlap) {
  Halves halves;
  for (int axis = 0; axis < 3; ++axis) {
    const auto [min, max] = std::minmax_element(
        points.begin(), points.end(),
        [axis](const auto& a, const auto& b) { return a.first[axis] < b.first[axis]; });
    halves.low_corner[axis] = min->first[axis];
    halves.high_corner[axis] = max->first[axis];
  }
  auto extent = [&](int axis) { return halves.high_corner[axis] - halves.low_corner[axis]; };
  for (int axis = 1; axis < 3; ++axis) {
    if (extent(axis) > extent(halves.axis)) halves.axis = axis;
  }
  std::vector<double> along;
  along.reserve(points.size());
  for (const auto& point : points) along.push_back(point.first[halves.axis]);
  std::nth_element(along.begin(), along.begin() + along.size() / 2, along.end());
  halves.at = along[along.size() / 2];
  for (const auto& point : points) {
    const double x = point.first[halves.axis];
    if (x < halves.at + overlap) halves.low.push_back(point);
    if (x >= halves.at - overlap) halves.high.push_back(point);
    if (x < halves.at) ++halves.below;
  }
  return halves;
}

// CGAL contours each half at the median of its function over all of that
// half's points, some of them near its open cut, where the function bends;
// the median over the points on the half's own side of the split is the
// contour value that matches the other half (without it the liver's volume
// moved by 0.05 % and its Hausdorff distance by 0.3 mm).
double own_side_median(const PoissonFunction& function, const Halves& halves, bool low) {
  // An input point is a vertex of its half's triangulation, so its value is
  // the vertex's (as in CGAL's own median).
  std::vector<double> values;
  const auto& tr = function.tr();
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v) {
    if (v->type() != PoissonFunction::Triangulation::INPUT) continue;
    const double x = v->point()[halves.axis];
    if (low ? x < halves.at : x >= halves.at) values.push_back(v->f());
  }
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Fewer seeds than CGAL's own 20 starting points: use those instead.
constexpr size_t kMinSeeds = 20;

// Delaunay refinement of the zero level of `function` inside a ball around
// `inner` (a point where the function is negative) of `radius`, from seeds
// spread over the level (mesher_seeds) near `points`.
absl::StatusOr<TriangleMesh> mesh_zero_level(const SolvedFunction& function, const Point& inner,
                                             double radius, const PoissonParams& params,
                                             const std::vector<OrientedPoint>& points,
                                             const std::function<void()>& beside_meshing) {
  // As in CGAL's examples, a ball well beyond the points. A crossing is
  // exact where a tetrahedron's linear piece holds it, and otherwise found
  // to a twentieth of the distance bound.
  const double ball_radius = 5 * radius;
  const double bisection_error = params.max_distance_mm / 20;
  ZeroLevel level{&function, Kernel::Sphere_3(inner, ball_radius * ball_radius),
                  bisection_error * bisection_error};
  // The liver asks about one crossing search per input point, small thin
  // shapes up to 25 (against a floor of 10,000); ten per point and 10,000
  // more leave a sound function room and stop a runaway one early.
  uint64_t crossings = 0;
  level.crossings = &crossings;
  level.max_crossings = 10 * (points.size() + 1000);
  // Seeds two voxels either side of the points (the surface is within about
  // one); too few for a start (a tiny piece) leave the mesher its own.
  const std::vector<Point> seeds =
      mesher_seeds(level, points, params.seed_spacing_mm, 4 * params.max_distance_mm);
  if (seeds.size() >= kMinSeeds) level.seeds = &seeds;
  CGAL::Surface_mesh_default_criteria_3<Triangulation> criteria(
      params.min_angle_deg, params.max_edge_mm / 2, params.max_distance_mm);
  Triangulation triangulation;
  Complex complex(triangulation);
  auto mesh_level = [&] {
    CGAL::make_surface_mesh(complex, level, ZeroLevelOracle(), criteria, CGAL::Manifold_tag());
  };
  bool budget_spent = false;
  auto bounded_mesh_level = [&] {
    try {
      mesh_level();
    } catch (const poisson::CrossingBudgetSpent&) {
      budget_spent = true;
    }
  };
  if (beside_meshing) {
    side_by_side(beside_meshing, bounded_mesh_level);
  } else {
    bounded_mesh_level();
  }
  if (budget_spent)
    return absl::InternalError(cat("poisson: the zero level needed more than ", level.max_crossings,
                                   " crossing searches: far more detail than the sizing"));
  auto mesh = complex_to_mesh(complex, triangulation);
  if (!mesh.ok())
    return absl::InternalError(cat("poisson: ", std::string(mesh.status().message())));
  if (mesh->triangles.empty())
    return absl::InternalError("poisson: meshing found no surface in the implicit function");
  return mesh;
}

absl::StatusOr<TriangleMesh> reconstruct_whole(const std::vector<OrientedPoint>& points,
                                               const PoissonParams& params,
                                               const RunContext& context, PoissonFigures& figures,
                                               const std::function<void()>& beside_meshing) {
  auto start = std::chrono::steady_clock::now();
  Solve whole = solve(points, params, context);
  figures.solver_iterations = whole.iterations;
  figures.solve_seconds = seconds_since(start);
  if (!whole.converged) return absl::InternalError("poisson: the linear solve did not converge");

  start = std::chrono::steady_clock::now();
  HintedEvaluator evaluator(*whole.function, context);
  const SolvedFunction function(&evaluator);
  auto mesh = mesh_zero_level(function, whole.function->get_inner_point(),
                              std::sqrt(whole.function->bounding_sphere().squared_radius()), params,
                              points, beside_meshing);
  figures.mesh_seconds = seconds_since(start);
  return mesh;
}

absl::StatusOr<TriangleMesh> reconstruct_in_halves(const std::vector<OrientedPoint>& points,
                                                   const PoissonParams& params,
                                                   const RunContext& context,
                                                   PoissonFigures& figures,
                                                   const std::function<void()>& beside_meshing) {
  auto start = std::chrono::steady_clock::now();
  const Halves halves = split_points(points, params.split_overlap_mm);
  // Many points on one plane across the split axis can leave the low side
  // (below the median) nearly empty: then one solve.
  if (halves.below < points.size() / 4)
    return reconstruct_whole(points, params, context, figures, beside_meshing);
  Solve low, high;
  side_by_side([&] { high = solve(halves.high, params, context); },
               [&] { low = solve(halves.low, params, context); });
  figures.solver_iterations = low.iterations + high.iterations;
  figures.solve_seconds = seconds_since(start);
  figures.solved_in_halves = true;
  if (!low.converged || !high.converged)
    return absl::InternalError("poisson: the linear solve did not converge");

  start = std::chrono::steady_clock::now();
  HintedEvaluator low_evaluator(*low.function, context), high_evaluator(*high.function, context);
  const double low_offset = own_side_median(*low.function, halves, true);
  const double high_offset = own_side_median(*high.function, halves, false);
  const SolvedFunction function(&low_evaluator, low_offset, &high_evaluator, high_offset,
                                halves.axis, halves.at, params.split_overlap_mm);
  // The mesher starts from a point inside: the deepest point of either half
  // that the blended function also puts inside.
  Point inner = low.function->get_inner_point();
  if (!(boost::get<0>(function.evaluate(inner)) < 0)) inner = high.function->get_inner_point();
  if (!(boost::get<0>(function.evaluate(inner)) < 0))
    return absl::InternalError("poisson: the halves' functions found no inside point");
  const auto& lo = halves.low_corner;
  const auto& hi = halves.high_corner;
  const Point centre((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const double half_diagonal =
      std::sqrt(CGAL::squared_distance(centre, Point(hi[0], hi[1], hi[2])));
  auto mesh = mesh_zero_level(function, inner,
                              half_diagonal + std::sqrt(CGAL::squared_distance(centre, inner)),
                              params, points, beside_meshing);
  figures.mesh_seconds = seconds_since(start);
  return mesh;
}

}  // namespace

absl::StatusOr<TriangleMesh> reconstruct_poisson_surface(
    const std::vector<geometry::Vec3>& points, const std::vector<geometry::Vec3>& normals,
    const PoissonParams& params, const RunContext& context, PoissonFigures& figures,
    const std::function<void()>& beside_meshing) {
  LABELMESH_RETURN_IF_ERROR(check_params(params));
  if (points.size() != normals.size())
    return absl::InternalError("poisson: one normal per point is needed");
  std::vector<OrientedPoint> oriented;
  oriented.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    const auto& n = normals[i];
    if (n[0] == 0 && n[1] == 0 && n[2] == 0) continue;
    oriented.emplace_back(Point(p[0], p[1], p[2]), Vector(n[0], n[1], n[2]));
  }
  figures.input_points = oriented.size();
  reduce_points(oriented, params, figures);
  figures.used_points = oriented.size();
  // Fewer points than a tetrahedron's worth leave nothing to solve on.
  if (oriented.size() < 10) {
    return absl::InvalidArgumentError(
        cat("poisson: ", oriented.size(), " oriented points are too few to reconstruct from"));
  }

  try {
    if (params.split_points != 0 && oriented.size() > params.split_points)
      return reconstruct_in_halves(oriented, params, context, figures, beside_meshing);
    return reconstruct_whole(oriented, params, context, figures, beside_meshing);
  } catch (const Cancelled&) {
    return absl::CancelledError("the run was cancelled");
  } catch (...) {
    // CGAL's failed preconditions and assertions, bad_alloc.
    return current_exception_status("poisson");
  }
}

}  // namespace labelmesh::surface
