// CGAL's surface mesher on a triangle surface: the implicit function is the
// surface's inside (a ray parity test on an AABB tree), its crossings found by
// bisection. Its own translation unit: the mesher's headers are slow to compile.
#include "core/surface/remesh_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/grid_simplify_point_set.h>
#include <CGAL/make_surface_mesh.h>

#include "core/surface/cgal_mesh.h"
#include "core/surface/restricted_delaunay.h"
#include "core/text.h"

namespace labelmesh::surface {
namespace {

using restricted_delaunay::Complex;
using restricted_delaunay::MesherTraits;
using restricted_delaunay::Triangulation;
using Point = cgal::Point;
using Inside = CGAL::Side_of_triangle_mesh<cgal::Mesh, cgal::Kernel>;

// The most inside tests one remeshing may make, and the largest surface it
// takes: ray parity costs 2-3 us a test on an organ of a few thousand
// triangles but 30 us on the brain's folded white matter (2 M tests took a
// minute there), so large surfaces are left to the other attempts.
constexpr uint64_t kMaxTests = 1'000'000;
constexpr size_t kMaxPoints = 60'000;

// Thrown from the inside test when the run is asked to stop.
struct Stopped {};
// Thrown when the mesher has asked more inside tests than its budget.
struct BudgetSpent {};

// Hash of a point's exact coordinates.
struct PointHash {
  size_t operator()(const Point& p) const {
    size_t h = 0;
    for (int i = 0; i < 3; ++i) h = h * 0x9E3779B97F4A7C15ull ^ std::hash<double>()(p[i]);
    return h;
  }
};

// -1 inside (or on) the surface, +1 outside; polls for a stop every 4,096
// tests. The mesher asks about the same Voronoi vertices again and again (an
// end of every dual edge it tests), so answers are remembered. A thin sheet
// can keep the mesher refining without end, so the tests are bounded.
class InsideFunction {
 public:
  InsideFunction(const Inside* inside, const RunContext* context, uint64_t max_tests)
      : inside_(inside), context_(context), max_tests_(max_tests) {}
  double operator()(const Point& p) const {
    auto [at, added] = state_->answers.try_emplace(p, 0.0);
    if (!added) return at->second;
    const uint64_t tests = ++state_->tests;
    if ((tests & 4095) == 0 && context_->stop_requested()) throw Stopped{};
    if (tests > max_tests_) throw BudgetSpent{};
    at->second = (*inside_)(p) == CGAL::ON_UNBOUNDED_SIDE ? 1.0 : -1.0;
    return at->second;
  }

 private:
  struct State {
    uint64_t tests = 0;
    std::unordered_map<Point, double, PointHash> answers;
  };
  const Inside* inside_;
  const RunContext* context_;
  uint64_t max_tests_;
  // std::function copies the functor; the answers are shared.
  std::shared_ptr<State> state_ = std::make_shared<State>();
};

absl::Status check_params(const RemeshParams& params) {
  if (!(params.min_angle_deg > 0 && params.min_angle_deg <= 30))
    return absl::InvalidArgumentError(
        cat("remesh min-angle: ", params.min_angle_deg, " is outside (0, 30] degrees"));
  if (!(params.max_edge_mm > 0) || !std::isfinite(params.max_edge_mm))
    return absl::InvalidArgumentError("remesh max-edge: must be a positive length");
  if (!(params.max_distance_mm > 0) || !std::isfinite(params.max_distance_mm))
    return absl::InvalidArgumentError("remesh max-distance: must be a positive length");
  return absl::OkStatus();
}

// A point strictly inside: a triangle's centre moved a little against its
// normal, for the first triangle where that lands inside.
std::optional<Point> inner_point(const TriangleMesh& surface, const Inside& inside) {
  for (const auto& t : surface.triangles) {
    const auto& a = surface.points[t[0]];
    const auto& b = surface.points[t[1]];
    const auto& c = surface.points[t[2]];
    const cgal::Kernel::Vector_3 u(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    const cgal::Kernel::Vector_3 v(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    const auto normal = CGAL::cross_product(u, v);
    const double length = std::sqrt(normal.squared_length());
    if (!(length > 0)) continue;
    // A tenth of the triangle's size inward.
    const double step = 0.1 * std::sqrt(length / 2);
    const Point centre((a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3,
                       (a[2] + b[2] + c[2]) / 3);
    const Point p = centre - normal * (step / length);
    if (inside(p) == CGAL::ON_BOUNDED_SIDE) return p;
  }
  return std::nullopt;
}

}  // namespace

absl::StatusOr<TriangleMesh> remesh_surface(const TriangleMesh& surface, const RemeshParams& params,
                                            const RunContext& context) {
  if (auto s = check_params(params); !s.ok()) return s;
  if (surface.points.size() > kMaxPoints)
    return absl::FailedPreconditionError(cat("remesh: the surface has ", surface.points.size(),
                                             " points, more than the ", kMaxPoints,
                                             " remeshing takes"));
  auto mesh = cgal::to_surface_mesh(surface);
  if (!mesh || mesh->is_empty() || !CGAL::is_closed(*mesh))
    return absl::InvalidArgumentError("remesh: the surface is not a closed 2-manifold");
  try {
    const Inside inside(*mesh);
    const auto inner = inner_point(surface, inside);
    if (!inner) return absl::InvalidArgumentError("remesh: the surface encloses no volume");
    CGAL::Bbox_3 box;
    for (const auto& p : surface.points) box += Point(p[0], p[1], p[2]).bbox();
    const Point low(box.xmin(), box.ymin(), box.zmin()), high(box.xmax(), box.ymax(), box.zmax());
    // A ball around the whole surface, centred inside it.
    const double radius = std::sqrt(std::max(CGAL::squared_distance(*inner, low),
                                             CGAL::squared_distance(*inner, high))) +
                          params.max_edge_mm;
    // Crossings to a twentieth of the distance bound (CGAL takes it relative
    // to the radius).
    const double relative_error = params.max_distance_mm / 20 / radius;
    CGAL::Implicit_surface_3<MesherTraits, InsideFunction> implicit(
        // TotalSegmentator's organs and bones take up to 40 tests per input
        // point; 150 (and 150,000 more) leave them room and stop a mesher
        // that does not settle within seconds. Never more than kMaxTests: a
        // large folded surface (the brain's white matter) would otherwise
        // take minutes and gigabytes of remembered answers.
        InsideFunction(&inside, &context,
                       std::min<uint64_t>(150 * (surface.points.size() + 1000), kMaxTests)),
        MesherTraits::Sphere_3(*inner, radius * radius), relative_error);
    // The mesher starts from the surface's own points, thinned to half an
    // edge apart, so every component is found however small.
    std::vector<Point> seeds = cgal::to_points(surface);
    seeds.erase(CGAL::grid_simplify_point_set(seeds, params.max_edge_mm / 2), seeds.end());
    Triangulation triangulation;
    triangulation.insert(seeds.begin(), seeds.end());
    Complex complex(triangulation);
    CGAL::Surface_mesh_default_criteria_3<Triangulation> criteria(
        params.min_angle_deg, params.max_edge_mm / 2, params.max_distance_mm);
    CGAL::make_surface_mesh(complex, implicit, criteria, CGAL::Manifold_tag(), 0);
    auto result = restricted_delaunay::complex_to_mesh(complex, triangulation);
    if (result.ok() && result->triangles.empty())
      return absl::InternalError("remesh: the mesher found no surface");
    return result;
  } catch (const Stopped&) {
    return absl::CancelledError("the run was cancelled");
  } catch (const BudgetSpent&) {
    return absl::InternalError(
        "remesh: the mesher did not settle within its budget of inside tests");
  } catch (const std::exception& e) {
    return absl::InternalError(cat("remesh: ", e.what()));
  }
}

}  // namespace labelmesh::surface
