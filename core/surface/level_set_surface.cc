// SPDX-License-Identifier: AGPL-3.0-or-later
// CGAL's surface mesher on a trilinearly interpolated voxel grid, its
// crossings found by bisection. Its own translation unit: the mesher's headers
// are slow to compile.
#include "core/surface/level_set_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>

#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Surface_mesh_default_criteria_3.h>
#include <CGAL/grid_simplify_point_set.h>
#include <CGAL/make_surface_mesh.h>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/surface/cgal/restricted_delaunay.h"
#include "core/util/exception_status.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::surface {
namespace {

using restricted_delaunay::Complex;
using restricted_delaunay::MesherTraits;
using restricted_delaunay::Triangulation;
using Point = cgal::Point;
using Vec3 = std::array<double, 3>;

// Fewer seeds than this are joined by crossings around the field's top.
constexpr size_t kFewSeeds = 20;

// Thrown from the field when the run is asked to stop.
struct Stopped {};
// Thrown when the mesher has asked more evaluations than its budget.
struct BudgetSpent {};

Vec3 multiply(const std::array<double, 9>& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

// The inverse of a 3x3 matrix by cofactors; nullopt when singular.
std::optional<std::array<double, 9>> inverse(const std::array<double, 9>& m) {
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return std::nullopt;
  return std::array<double, 9>{(m[4] * m[8] - m[5] * m[7]) / det, (m[2] * m[7] - m[1] * m[8]) / det,
                               (m[1] * m[5] - m[2] * m[4]) / det, (m[5] * m[6] - m[3] * m[8]) / det,
                               (m[0] * m[8] - m[2] * m[6]) / det, (m[2] * m[3] - m[0] * m[5]) / det,
                               (m[3] * m[7] - m[4] * m[6]) / det, (m[1] * m[6] - m[0] * m[7]) / det,
                               (m[0] * m[4] - m[1] * m[3]) / det};
}

// The field's trilinear interpolation in patient space.
class Field {
 public:
  Field(const ScalarGrid& grid, const std::array<double, 9>& mm_to_index)
      : grid_(grid), mm_to_index_(mm_to_index) {}

  Vec3 to_index(const Vec3& p) const {
    return multiply(mm_to_index_,
                    {p[0] - grid_.origin[0], p[1] - grid_.origin[1], p[2] - grid_.origin[2]});
  }
  Vec3 to_mm(const Vec3& index) const {
    const Vec3 d = multiply(grid_.index_to_mm, index);
    return {grid_.origin[0] + d[0], grid_.origin[1] + d[1], grid_.origin[2] + d[2]};
  }

  // The interpolated value at a continuous index; `outside` off the grid.
  double at_index(const Vec3& x, double outside) const {
    std::array<int64_t, 3> cell{};
    std::array<double, 3> t{};
    for (int a = 0; a < 3; ++a) {
      if (!(x[a] >= 0 && x[a] <= double(grid_.dims[a] - 1))) return outside;
      cell[a] =
          std::min<int64_t>(static_cast<int64_t>(x[a]), std::max<int64_t>(grid_.dims[a] - 2, 0));
      t[a] = x[a] - double(cell[a]);
    }
    const int64_t nx = grid_.dims[0], nxy = grid_.dims[0] * grid_.dims[1];
    const int64_t dx = grid_.dims[0] > 1 ? 1 : 0, dy = grid_.dims[1] > 1 ? nx : 0,
                  dz = grid_.dims[2] > 1 ? nxy : 0;
    const float* v = grid_.values.data() + cell[0] + cell[1] * nx + cell[2] * nxy;
    const double x00 = v[0] + t[0] * (v[dx] - v[0]);
    const double x10 = v[dy] + t[0] * (v[dy + dx] - v[dy]);
    const double x01 = v[dz] + t[0] * (v[dz + dx] - v[dz]);
    const double x11 = v[dz + dy] + t[0] * (v[dz + dy + dx] - v[dz + dy]);
    const double y0 = x00 + t[1] * (x10 - x00);
    const double y1 = x01 + t[1] * (x11 - x01);
    return y0 + t[2] * (y1 - y0);
  }

 private:
  const ScalarGrid& grid_;
  std::array<double, 9> mm_to_index_;
};

// CGAL's implicit function: negative inside (above the level), positive
// outside; polls for a stop every 65,536 evaluations and stops the mesher
// at its budget (a thin sheet can keep it refining without end).
class LevelFunction {
 public:
  LevelFunction(const Field* field, double level, const RunContext* context,
                uint64_t max_evaluations)
      : field_(field),
        level_(level),
        context_(context),
        max_evaluations_(max_evaluations),
        evaluations_(std::make_shared<uint64_t>(0)) {}
  double operator()(const Point& p) const {
    const uint64_t n = ++*evaluations_;
    if ((n & 65535) == 0 && context_->stop_requested()) throw Stopped{};
    if (n > max_evaluations_) throw BudgetSpent{};
    return level_ - field_->at_index(field_->to_index({p.x(), p.y(), p.z()}), level_ - 1);
  }
  uint64_t evaluations() const { return *evaluations_; }

 private:
  const Field* field_;
  double level_;
  const RunContext* context_;
  uint64_t max_evaluations_;
  // std::function copies the functor; the count is shared.
  std::shared_ptr<uint64_t> evaluations_;
};

absl::Status check_input(const ScalarGrid& grid, const LevelSetParams& params) {
  if (!(params.min_angle_deg > 0 && params.min_angle_deg <= 30))
    return absl::InvalidArgumentError(
        cat("level-set min-angle: ", params.min_angle_deg, " is outside (0, 30] degrees"));
  if (!(params.max_edge_mm > 0) || !std::isfinite(params.max_edge_mm))
    return absl::InvalidArgumentError("level-set max-edge: must be a positive length");
  if (!(params.max_distance_mm > 0) || !std::isfinite(params.max_distance_mm))
    return absl::InvalidArgumentError("level-set max-distance: must be a positive length");
  if (!std::isfinite(params.level))
    return absl::InvalidArgumentError("level-set level: must be finite");
  uint64_t count = 1;
  for (int64_t n : grid.dims) {
    if (n < 2) return absl::InvalidArgumentError("level-set grid: each side needs 2 samples");
    // Checked before multiplying, so the count cannot wrap around.
    if (uint64_t(n) > grid.values.size() / count)
      return absl::InvalidArgumentError(
          cat("level-set grid: ", grid.values.size(), " values for more voxels"));
    count *= uint64_t(n);
  }
  if (count != grid.values.size())
    return absl::InvalidArgumentError(
        cat("level-set grid: ", grid.values.size(), " values for ", count, " voxels"));
  return absl::OkStatus();
}

// Moves a point onto the level set by up to six Newton steps along the
// field's gradient (central differences half a voxel apart, in grid index
// space); nullopt when it does not land within 0.01 of the level (a mask
// runs from 0 to 1), or strays more than a voxel along any axis.
std::optional<Vec3> onto_level(const Field& field, double level, const Vec3& start_index) {
  Vec3 x = start_index;
  for (int step = 0;; ++step) {
    const double value = field.at_index(x, level - 1) - level;
    if (std::abs(value) < 0.01) return x;
    if (step == 6) return std::nullopt;
    Vec3 gradient{};
    double norm2 = 0;
    for (int a = 0; a < 3; ++a) {
      Vec3 lo = x, hi = x;
      lo[a] -= 0.25;
      hi[a] += 0.25;
      gradient[a] = (field.at_index(hi, level - 1) - field.at_index(lo, level - 1)) / 0.5;
      norm2 += gradient[a] * gradient[a];
    }
    if (!(norm2 > 1e-12)) return std::nullopt;
    for (int a = 0; a < 3; ++a) x[a] -= value * gradient[a] / norm2;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(x[a] - start_index[a]) > 1) return std::nullopt;
    }
  }
}

// Where the field crosses the level along the 26 grid directions from
// `centre` (an index above the level): found by quarter-voxel steps, then
// bisection. A small component's seeds, thinned to half an edge apart, can be
// too few for the mesher's first triangulation (it needs four points not in
// one plane); these make up for them.
std::vector<Vec3> crossings_around(const Field& field, double level, const Vec3& centre) {
  std::vector<Vec3> found;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Vec3 direction{0.25 * dx, 0.25 * dy, 0.25 * dz};
        auto at = [&](double t) {
          return Vec3{centre[0] + t * direction[0], centre[1] + t * direction[1],
                      centre[2] + t * direction[2]};
        };
        // Off the grid the field is below the level, so every ray crosses.
        double inside = 0, outside = 1;
        while (field.at_index(at(outside), level - 1) > level) inside = outside++;
        for (int i = 0; i < 30; ++i) {
          const double middle = (inside + outside) / 2;
          (field.at_index(at(middle), level - 1) > level ? inside : outside) = middle;
        }
        found.push_back(at((inside + outside) / 2));
      }
    }
  }
  return found;
}

}  // namespace

absl::StatusOr<TriangleMesh> mesh_level_set(const ScalarGrid& grid, const LevelSetParams& params,
                                            const std::vector<std::array<double, 3>>& seeds,
                                            const RunContext& context) {
  LABELMESH_RETURN_IF_ERROR(check_input(grid, params));
  const auto mm_to_index = inverse(grid.index_to_mm);
  if (!mm_to_index) return absl::InvalidArgumentError("level-set grid: singular placement");
  const Field field(grid, *mm_to_index);
  // The mesher starts from the seeds, thinned to half an edge apart and moved
  // onto the level set, so every component is found however small.
  std::vector<Point> thinned;
  thinned.reserve(seeds.size());
  for (const auto& s : seeds) thinned.emplace_back(s[0], s[1], s[2]);
  thinned.erase(CGAL::grid_simplify_point_set(thinned, params.max_edge_mm / 2), thinned.end());
  std::vector<Point> on_level;
  for (const auto& p : thinned) {
    if (auto x = onto_level(field, params.level, field.to_index({p.x(), p.y(), p.z()}))) {
      const Vec3 q = field.to_mm(*x);
      on_level.emplace_back(q[0], q[1], q[2]);
    }
  }
  // The centre of the mesher's ball: the sample furthest above the level.
  const auto top = std::max_element(grid.values.begin(), grid.values.end());
  if (on_level.empty() || !(*top > params.level))
    return absl::InvalidArgumentError("level-set: no seed on the level set, or nothing inside");
  const int64_t at = top - grid.values.begin();
  const Vec3 centre_index{double(at % grid.dims[0]), double(at / grid.dims[0] % grid.dims[1]),
                          double(at / (grid.dims[0] * grid.dims[1]))};
  const Vec3 centre = field.to_mm(centre_index);
  if (on_level.size() < kFewSeeds) {
    for (const auto& x : crossings_around(field, params.level, centre_index)) {
      const Vec3 q = field.to_mm(x);
      on_level.emplace_back(q[0], q[1], q[2]);
    }
  }
  // A ball around the whole grid.
  double radius2 = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 c = field.to_mm({corner & 1 ? double(grid.dims[0] - 1) : 0,
                                corner & 2 ? double(grid.dims[1] - 1) : 0,
                                corner & 4 ? double(grid.dims[2] - 1) : 0});
    double d2 = 0;
    for (int a = 0; a < 3; ++a) d2 += (c[a] - centre[a]) * (c[a] - centre[a]);
    radius2 = std::max(radius2, d2);
  }
  const double radius = std::sqrt(radius2) + params.max_edge_mm;
  try {
    // Crossings to a twentieth of the distance bound (CGAL takes it relative
    // to the radius). TotalSegmentator's labels took at most 340
    // evaluations per seed (and 340,000 more), so the budget of 2,000 per seed
    // (and 2,000,000 more) stops one that does not settle within about six
    // times what the worst of them needed.
    const uint64_t budget = 2'000 * (on_level.size() + 1000);
    const LevelFunction function(&field, params.level, &context, budget);
    CGAL::Implicit_surface_3<MesherTraits, LevelFunction> implicit(
        function, MesherTraits::Sphere_3(Point(centre[0], centre[1], centre[2]), radius * radius),
        params.max_distance_mm / 20 / radius);
    Triangulation triangulation;
    triangulation.insert(on_level.begin(), on_level.end());
    Complex complex(triangulation);
    CGAL::Surface_mesh_default_criteria_3<Triangulation> criteria(
        params.min_angle_deg, params.max_edge_mm / 2, params.max_distance_mm);
    CGAL::make_surface_mesh(complex, implicit, criteria, CGAL::Manifold_tag(), 0);
    auto result = restricted_delaunay::complex_to_mesh(complex, triangulation);
    if (result.ok() && result->triangles.empty())
      return absl::InternalError("level-set: the mesher found no surface");
    return result;
  } catch (const Stopped&) {
    return absl::CancelledError("the run was cancelled");
  } catch (const BudgetSpent&) {
    return absl::ResourceExhaustedError(
        "level-set: the mesher did not settle within its budget of field evaluations");
  } catch (...) {
    return current_exception_status("level-set");
  }
}

}  // namespace labelmesh::surface
