// The only translation unit that instantiates CGAL's Poisson reconstruction and
// surface mesher: it is slow to compile, so nothing else includes these headers.
#include "core/surface/poisson_surface.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <unordered_map>
#include <utility>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_with_circumcenter_3.h>
#include <CGAL/Poisson_implicit_surface_3.h>
#include <CGAL/Poisson_reconstruction_function.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Robust_circumcenter_traits_3.h>
#include <CGAL/Surface_mesh_cell_base_3.h>
#include <CGAL/Surface_mesh_complex_2_in_triangulation_3.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/Surface_mesh_vertex_base_3.h>
#include <CGAL/grid_simplify_point_set.h>
#include <CGAL/hierarchy_simplify_point_set.h>
#include <CGAL/make_surface_mesh.h>
#include <CGAL/property_map.h>
#include <Eigen/IterativeLinearSolvers>

#include "core/surface/cgal_mesh.h"
#include "core/text.h"

namespace labelmesh::surface {
namespace {

using cgal::Kernel;
using cgal::Point;
using Vector = Kernel::Vector_3;
using OrientedPoint = std::pair<Point, Vector>;
using PointMap = CGAL::First_of_pair_property_map<OrientedPoint>;
using NormalMap = CGAL::Second_of_pair_property_map<OrientedPoint>;
using PoissonFunction = CGAL::Poisson_reconstruction_function<Kernel>;

// Thrown from inside CGAL's loops when a stop is requested; caught below.
struct Cancelled {};

// CGAL calls this before inserting each input point into its triangulation.
struct CancellableInsertion {
  const RunContext* context;
  void before_insertion() const {
    if (context->stop_requested()) throw Cancelled{};
  }
};

// Eigen's Jacobi preconditioner, which conjugate gradient applies once per
// iteration: the one hook inside the solve where a stop request can be seen.
class CancellablePreconditioner : public Eigen::DiagonalPreconditioner<double> {
 public:
  void set_context(const RunContext* context) { context_ = context; }

  template <typename Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    if (context_ != nullptr && context_->stop_requested()) throw Cancelled{};
    return Eigen::DiagonalPreconditioner<double>::solve(b);
  }

 private:
  const RunContext* context_ = nullptr;
};

// Conjugate gradient to a relative residual, cancellable at every iteration;
// a model of CGAL's SparseLinearAlgebraTraits_d.
class CancellableSolver {
 public:
  using Matrix = CGAL::Eigen_sparse_symmetric_matrix<double>;
  using Vector = CGAL::Eigen_vector<double>;
  using NT = double;

  CancellableSolver(const RunContext* context, double tolerance, int* iterations)
      : context_(context), tolerance_(tolerance), iterations_(iterations) {}

  bool linear_solver(const Matrix& a, const Vector& b, Vector& x, NT& d) {
    d = 1;
    // CGAL stores the lower triangle of the symmetric matrix.
    Eigen::ConjugateGradient<Matrix::EigenType, Eigen::Lower, CancellablePreconditioner> solver;
    solver.preconditioner().set_context(context_);
    solver.setTolerance(tolerance_);
    solver.compute(a.eigen_object());
    if (solver.info() != Eigen::Success) return false;
    x = solver.solve(b);
    *iterations_ += static_cast<int>(solver.iterations());
    return solver.info() == Eigen::Success;
  }

 private:
  const RunContext* context_;
  double tolerance_;
  int* iterations_;
};

// Evaluates the solved implicit function for the surface mesher. Each value
// means locating the point in the solve's triangulation, and CGAL walks there
// from its previous answer; the mesher's queries jump across the surface, so
// on the liver 3.3 M such walks took 3.7 of the 5 s of meshing (1.7 s now).
// Here a long jump starts from the cell first found in the query's cube of a
// coarse grid, and the oracle's second question about a segment's ends (it
// asks for their sign, then for their value and cell) is answered from the
// last answers.
// Every answer depends only on the order of the queries, so meshing stays
// deterministic. Polls for a stop every few thousand evaluations.
class HintedEvaluator {
 public:
  using FT = Kernel::FT;
  using Triangulation = PoissonFunction::Triangulation;
  using Cell_handle = PoissonFunction::Cell_handle;
  using Answer = boost::tuple<FT, Cell_handle, bool>;

  HintedEvaluator(const PoissonFunction& function, const RunContext& context)
      : tr_(function.tr()), context_(context) {
    const CGAL::Bbox_3 box = CGAL::bbox_3(tr_.points_begin(), tr_.points_end());
    const double volume =
        (box.xmax() - box.xmin()) * (box.ymax() - box.ymin()) * (box.zmax() - box.zmin());
    const double longest =
        std::max({box.xmax() - box.xmin(), box.ymax() - box.ymin(), box.zmax() - box.zmin(), 1e-9});
    // About two million cubes (16 MB): a few cells across each on the liver.
    // The second bound keeps a flat or empty box from asking for more.
    step_ = std::max(std::cbrt(volume / double(1 << 21)), longest / 1024);
    origin_ = {box.xmin(), box.ymin(), box.zmin()};
    for (int axis = 0; axis < 3; ++axis)
      size_[axis] = int((box.max(axis) - box.min(axis)) / step_) + 1;
    slots_.assign(size_t(size_[0]) * size_[1] * size_[2], Cell_handle());
    last_ = tr_.infinite_cell();
  }

  Answer evaluate(const Point& p) {
    for (const auto& [point, answer] : recent_) {
      if (point == p) return answer;
    }
    if ((++calls_ & 4095) == 0 && context_.stop_requested()) throw Cancelled{};
    // Bisection asks next door to its last question: walk from there.
    Cell_handle* slot = slot_for(p);
    const bool near_last = CGAL::squared_distance(p, last_point_) < step_ * step_;
    const Cell_handle start =
        !near_last && slot != nullptr && *slot != Cell_handle() ? *slot : last_;
    const Cell_handle cell = tr_.locate(p, start);
    if (slot != nullptr && *slot == Cell_handle()) *slot = cell;
    last_ = cell;
    last_point_ = p;
    const Answer answer = value_in(cell, p);
    recent_[next_recent_] = {p, answer};
    next_recent_ = (next_recent_ + 1) % recent_.size();
    return answer;
  }

 private:
  Cell_handle* slot_for(const Point& p) {
    size_t index = 0;
    for (int axis = 2; axis >= 0; --axis) {
      const double at = (p[axis] - origin_[axis]) / step_;
      if (!(at >= 0 && at < size_[axis])) return nullptr;
      index = index * size_[axis] + size_t(at);
    }
    return &slots_[index];
  }

  // Linear interpolation of the vertex values, as CGAL's own operator();
  // outside the convex hull, the value of a hull vertex.
  Answer value_in(Cell_handle cell, const Point& p) const {
    if (tr_.is_infinite(cell)) {
      const int i = cell->index(tr_.infinite_vertex());
      return {cell->vertex((i + 1) & 3)->f(), cell, true};
    }
    const Point& d = cell->vertex(3)->point();
    const Vector da = cell->vertex(0)->point() - d, db = cell->vertex(1)->point() - d,
                 dc = cell->vertex(2)->point() - d, dp = p - d;
    const double whole = CGAL::determinant(da, db, dc);
    const double a = CGAL::determinant(dp, db, dc) / whole;
    const double b = CGAL::determinant(da, dp, dc) / whole;
    const double c = CGAL::determinant(da, db, dp) / whole;
    const double value = a * cell->vertex(0)->f() + b * cell->vertex(1)->f() +
                         c * cell->vertex(2)->f() + (1 - a - b - c) * cell->vertex(3)->f();
    return {value, cell, false};
  }

  const Triangulation& tr_;
  const RunContext& context_;
  double step_ = 1;
  std::array<double, 3> origin_{};
  std::array<int, 3> size_{};
  std::vector<Cell_handle> slots_;
  Cell_handle last_;
  Point last_point_ = Point(CGAL::ORIGIN);
  std::array<std::pair<Point, Answer>, 4> recent_{};
  size_t next_recent_ = 0;
  uint32_t calls_ = 0;
};

// The function as CGAL's Poisson surface oracle calls it; the mesher copies
// it freely, so it only points at the evaluator.
class MesherFunction {
 public:
  using FT = Kernel::FT;
  using Point = Kernel::Point_3;
  using Cell_handle = PoissonFunction::Cell_handle;

  explicit MesherFunction(HintedEvaluator* evaluator) : evaluator_(evaluator) {}

  FT operator()(const Point& p) const { return boost::get<0>(evaluator_->evaluate(p)); }
  HintedEvaluator::Answer special_func(const Point& p) const { return evaluator_->evaluate(p); }

 private:
  HintedEvaluator* evaluator_;
};

// Adds CGAL's creation-order time stamp to a vertex or cell base. CGAL then
// orders and hashes handles by that stamp instead of by address, so the
// surface mesher's sets of bad vertices and edges are walked in the same order
// in every process (the default triangulation gave the liver 15,798 nodes in
// the CLI and 15,890 in the server's worker).
template <class Base>
class TimeStamped : public Base {
 public:
  using Has_timestamp = CGAL::Tag_true;
  template <class Tds>
  struct Rebind_TDS {
    using Other = TimeStamped<typename Base::template Rebind_TDS<Tds>::Other>;
  };
  using Base::Base;

  std::size_t time_stamp() const { return time_stamp_; }
  void set_time_stamp(std::size_t stamp) { time_stamp_ = stamp; }

 private:
  std::size_t time_stamp_ = std::size_t(-1);
};

// CGAL's Surface_mesh_default_triangulation_3 with time-stamped bases.
using MesherTraits = CGAL::Robust_circumcenter_traits_3<Kernel>;
using MesherVertexBase = TimeStamped<CGAL::Surface_mesh_vertex_base_3<MesherTraits>>;
using MesherCellBase = TimeStamped<CGAL::Delaunay_triangulation_cell_base_with_circumcenter_3<
    MesherTraits, CGAL::Surface_mesh_cell_base_3<MesherTraits>>>;
using Triangulation = CGAL::Delaunay_triangulation_3<
    MesherTraits, CGAL::Triangulation_data_structure_3<MesherVertexBase, MesherCellBase>>;
using Complex = CGAL::Surface_mesh_complex_2_in_triangulation_3<Triangulation>;
using ImplicitSurface = CGAL::Poisson_implicit_surface_3<Kernel, MesherFunction>;
using OutputMesh = cgal::Mesh;

// The triangles of the restricted Delaunay surface, in the triangulation's
// own (deterministic) vertex order, oriented outward by CGAL (which handles
// nested components), and sorted so the order never depends on addresses.
absl::StatusOr<TriangleMesh> complex_to_mesh(const Complex& complex, const Triangulation& tr) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<std::array<Triangulation::Vertex_handle, 3>> facets;
  for (auto f = tr.finite_facets_begin(); f != tr.finite_facets_end(); ++f) {
    if (!complex.is_in_complex(*f)) continue;
    const auto cell = f->first;
    const int i = f->second;
    facets.push_back({cell->vertex(tr.vertex_triple_index(i, 0)),
                      cell->vertex(tr.vertex_triple_index(i, 1)),
                      cell->vertex(tr.vertex_triple_index(i, 2))});
  }
  std::unordered_map<Triangulation::Vertex_handle, size_t> index;
  for (const auto& facet : facets) {
    for (auto v : facet) index.emplace(v, 0);
  }
  std::vector<Point> points;
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v) {
    auto found = index.find(v);
    if (found == index.end()) continue;
    found->second = points.size();
    points.push_back(v->point());
  }
  std::vector<std::array<size_t, 3>> triangles;
  triangles.reserve(facets.size());
  for (const auto& f : facets) triangles.push_back({index[f[0]], index[f[1]], index[f[2]]});
  PMP::orient_polygon_soup(points, triangles);
  if (!PMP::is_polygon_soup_a_polygon_mesh(triangles))
    return absl::InternalError("poisson: the meshed surface is not a manifold");
  OutputMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, triangles, mesh);
  PMP::orient_to_bound_a_volume(mesh);
  TriangleMesh result = cgal::from_surface_mesh(mesh);
  for (auto& t : result.triangles)
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(result.triangles.begin(), result.triangles.end());
  return result;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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
  if (params.reduction == PointReduction::kHierarchy &&
      !(params.cluster_size >= 1 && params.cluster_size <= kMaxClusterSize))
    return absl::InvalidArgumentError(
        cat("point-cluster-size: ", params.cluster_size, " is outside 1..", kMaxClusterSize));
  return absl::OkStatus();
}

void reduce_points(std::vector<OrientedPoint>& points, const PoissonParams& params) {
  switch (params.reduction) {
    case PointReduction::kNone:
      return;
    case PointReduction::kGrid:
      points.erase(CGAL::grid_simplify_point_set(points, params.reduction_cell_mm,
                                                 CGAL::parameters::point_map(PointMap())),
                   points.end());
      return;
    case PointReduction::kHierarchy:
      // CGAL's variation bound stays at its default: any 3 points are
      // coplanar, so at the sizes worth using the size decides.
      points.erase(CGAL::hierarchy_simplify_point_set(
                       points, CGAL::parameters::point_map(PointMap()).size(params.cluster_size)),
                   points.end());
      return;
  }
}

}  // namespace

absl::StatusOr<TriangleMesh> reconstruct_poisson_surface(const std::vector<geometry::Vec3>& points,
                                                         const std::vector<geometry::Vec3>& normals,
                                                         const PoissonParams& params,
                                                         const RunContext& context,
                                                         PoissonFigures& figures) {
  if (auto s = check_params(params); !s.ok()) return s;
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
  reduce_points(oriented, params);
  figures.used_points = oriented.size();
  // Fewer points than a tetrahedron's worth leave nothing to solve on.
  if (oriented.size() < 10) {
    return absl::InvalidArgumentError(
        cat("poisson: ", oriented.size(), " oriented points are too few to reconstruct from"));
  }

  try {
    auto start = std::chrono::steady_clock::now();
    PoissonFunction function(oriented.begin(), oriented.end(), PointMap(), NormalMap(),
                             CancellableInsertion{&context});
    CancellableSolver solver(&context, params.solver_tolerance, &figures.solver_iterations);
    const bool solved = function.compute_implicit_function(solver, CancellableInsertion{&context});
    figures.solve_seconds = seconds_since(start);
    if (!solved) return absl::InternalError("poisson: the linear solve did not converge");

    start = std::chrono::steady_clock::now();
    const Point inner = function.get_inner_point();
    const double radius = std::sqrt(function.bounding_sphere().squared_radius());
    // As in CGAL's examples, a ball well beyond the points. Bisection of a
    // crossing stops at a twentieth of the distance bound (CGAL solves exactly
    // once both ends share a tetrahedron, where the function is linear).
    const double ball_radius = 5 * radius;
    const double bisection_error = params.max_distance_mm / 20 / ball_radius;
    HintedEvaluator evaluator(function, context);
    ImplicitSurface surface(MesherFunction(&evaluator),
                            Kernel::Sphere_3(inner, ball_radius * ball_radius), bisection_error);
    CGAL::Surface_mesh_default_criteria_3<Triangulation> criteria(
        params.min_angle_deg, params.max_edge_mm / 2, params.max_distance_mm);
    Triangulation triangulation;
    Complex complex(triangulation);
    CGAL::make_surface_mesh(complex, surface, criteria, CGAL::Manifold_tag());
    auto mesh = complex_to_mesh(complex, triangulation);
    if (mesh.ok() && mesh->triangles.empty())
      return absl::InternalError("poisson: meshing found no surface in the implicit function");
    figures.mesh_seconds = seconds_since(start);
    return mesh;
  } catch (const Cancelled&) {
    return absl::CancelledError("the run was cancelled");
  }
}

}  // namespace labelmesh::surface
