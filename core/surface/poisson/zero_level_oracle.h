// SPDX-License-Identifier: AGPL-3.0-or-later
// The solved Poisson function as the surface mesher sees it: one solve or two
// blended halves, and the oracle that finds where the mesher's segments cross
// its zero level. Included only by the Poisson translation unit and its test:
// CGAL's Poisson and surface mesher headers are slow to compile.
#pragma once

#include <algorithm>
#include <optional>
#include <vector>

#include <CGAL/Object.h>
#include <CGAL/Random.h>
#include <CGAL/Surface_mesher/Sphere_oracle_3.h>
#include <CGAL/point_generators_3.h>

#include "core/surface/poisson/hinted_poisson_evaluator.h"

namespace labelmesh::surface::poisson {

// The function that is meshed: one solve, or two solves of overlapping
// halves of the points blended across the middle of the overlap.
class SolvedFunction {
 public:
  using Answer = HintedEvaluator::Answer;
  using Cell_handle = HintedEvaluator::Cell_handle;

  explicit SolvedFunction(HintedEvaluator* whole) : low_(whole) {}

  // `low` holds the points below `at` along `axis`, `high` those above, each
  // reaching `overlap` past `at`; the offsets are subtracted from each.
  SolvedFunction(HintedEvaluator* low, double low_offset, HintedEvaluator* high, double high_offset,
                 int axis, double at, double overlap)
      : low_(low),
        high_(high),
        low_offset_(low_offset),
        high_offset_(high_offset),
        axis_(axis),
        blend_from_(at - overlap / 2),
        blend_width_(overlap) {}

  Answer evaluate(const Point& p) const {
    if (high_ == nullptr) return low_->evaluate(p);
    const double t = blend_at(p);
    if (t <= 0) return shifted(low_->evaluate(p), low_offset_);
    if (t >= 1) return shifted(high_->evaluate(p), high_offset_);
    // Smoothstep: the blend and its slope are continuous at both ends.
    const double w = t * t * (3 - 2 * t);
    const auto low = low_->evaluate(p), high = high_->evaluate(p);
    const double value =
        (1 - w) * (boost::get<0>(low) - low_offset_) + w * (boost::get<0>(high) - high_offset_);
    // The cell lets the oracle interpolate linearly once a crossing's ends
    // share one. The blend is not linear within a cell, so that crossing is an
    // approximation, within one cell of the surface; the blend changes over
    // 20 voxels, the cells there are about one voxel across.
    const auto& nearer = w < 0.5 ? low : high;
    return {value, boost::get<1>(nearer), boost::get<2>(nearer)};
  }

  // The exact zero on [p1, p2] within `cell`, the cell answered for `probe`,
  // where the function is that cell's linear piece: not in the blend.
  std::optional<Point> zero_in_cell(const Point& probe, Cell_handle cell, const Point& p1,
                                    const Point& p2) const {
    if (high_ == nullptr) return low_->zero_in_cell(cell, 0, p1, p2);
    const double t = blend_at(probe);
    std::optional<Point> zero;
    if (t <= 0) {
      zero = low_->zero_in_cell(cell, low_offset_, p1, p2);
      if (zero && blend_at(*zero) > 0) zero.reset();
    } else if (t >= 1) {
      zero = high_->zero_in_cell(cell, high_offset_, p1, p2);
      if (zero && blend_at(*zero) < 1) zero.reset();
    }
    return zero;
  }

 private:
  static Answer shifted(Answer answer, double offset) {
    boost::get<0>(answer) -= offset;
    return answer;
  }

  double blend_at(const Point& p) const { return (p[axis_] - blend_from_) / blend_width_; }

  HintedEvaluator* low_;
  HintedEvaluator* high_ = nullptr;
  double low_offset_ = 0, high_offset_ = 0;
  int axis_ = 0;
  double blend_from_ = 0, blend_width_ = 1;
};

// What the surface mesher meshes: the zero level of `function` inside
// `sphere`, with crossings found to within `squared_error` (squared length).
// With `seeds`, the mesher starts from those points of the level instead of
// a few found along rays from the sphere's centre.
struct ZeroLevel {
  const SolvedFunction* function;
  Kernel::Sphere_3 sphere;
  double squared_error;
  const std::vector<Point>* seeds = nullptr;
  // Crossings searched so far, and the most allowed (0: no bound). A
  // function whose zero level holds far more detail than the sizing (specks
  // of a thin shape's function, say) would otherwise keep the mesher going
  // for minutes.
  uint64_t* crossings = nullptr;
  uint64_t max_crossings = 0;
};

// Thrown by the oracle when a ZeroLevel's crossing budget is spent.
struct CrossingBudgetSpent {};

// The surface mesher's oracle (CGAL's SurfaceMeshTraits_3) for a ZeroLevel.
// CGAL's Poisson oracle bisects each crossing segment until both ends share a
// tetrahedron of the solve, then interpolates. Here each step probes where
// the straight line through the ends' values crosses zero (false position),
// and a probe whose tetrahedron holds the zero of its linear piece ends the
// search there, exactly. Every third step bisects, so a bracket whose one end
// stays put still halves. On a torus that takes 3.3 located points a crossing
// where bisection takes 7.2; where the zero lies in a sliver too thin to
// tell inside from outside, both end at the error bound.
class ZeroLevelOracle {
 public:
  using Geom_traits = Kernel;
  using Point_3 = Point;
  using Segment_3 = Kernel::Segment_3;
  using Ray_3 = Kernel::Ray_3;
  using Line_3 = Kernel::Line_3;
  using Surface_3 = ZeroLevel;
  using Intersection_point = Point;

  class Intersect_3 {
   public:
    CGAL::Object operator()(const ZeroLevel& level, const Segment_3& segment) const {
      Point a = segment.source(), b = segment.target();
      const auto at_a = level.function->evaluate(a), at_b = level.function->evaluate(b);
      if (CGAL::sign(boost::get<0>(at_a)) == CGAL::sign(boost::get<0>(at_b))) return {};
      if (!clip().clip_segment(level.sphere, a, b)) return {};
      return crossing(level, a, b);
    }

    CGAL::Object operator()(const ZeroLevel& level, const Ray_3& ray) const {
      Point a, b;
      if (!clip().clip_ray(level.sphere, ray, a, b)) return {};
      return crossing(level, a, b);
    }

    CGAL::Object operator()(const ZeroLevel& level, const Line_3& line) const {
      Point a, b;
      if (!clip().clip_line(level.sphere, line, a, b)) return {};
      return crossing(level, a, b);
    }

   private:
    using Clip = CGAL::Surface_mesher::Sphere_oracle_3<Kernel>::Intersect_3;
    static Clip clip() {
      return CGAL::Surface_mesher::Sphere_oracle_3<Kernel>().intersect_3_object();
    }

    static CGAL::Object crossing(const ZeroLevel& level, Point p1, Point p2) {
      if (level.crossings != nullptr && ++*level.crossings > level.max_crossings &&
          level.max_crossings != 0)
        throw CrossingBudgetSpent{};
      const SolvedFunction& function = *level.function;
      double v1, v2;
      SolvedFunction::Cell_handle c1, c2;
      bool infinite1, infinite2;
      boost::tie(v1, c1, infinite1) = function.evaluate(p1);
      boost::tie(v2, c2, infinite2) = function.evaluate(p2);
      if (CGAL::sign(v1) == CGAL::sign(v2)) return {};
      for (int step = 0;; ++step) {
        if (c1 == c2) {
          if (infinite1) return {};
          // The function is linear between two points of one cell.
          return CGAL::make_object(
              CGAL::ORIGIN + ((v2 * (p1 - CGAL::ORIGIN)) - (v1 * (p2 - CGAL::ORIGIN))) / (v2 - v1));
        }
        if (CGAL::squared_distance(p1, p2) < level.squared_error)
          return CGAL::make_object(CGAL::midpoint(p1, p2));
        const Point probe =
            step % 3 == 2 ? CGAL::midpoint(p1, p2) : p1 + (v1 / (v1 - v2)) * (p2 - p1);
        double value;
        SolvedFunction::Cell_handle cell;
        bool infinite;
        boost::tie(value, cell, infinite) = function.evaluate(probe);
        if (value == 0) return CGAL::make_object(probe);
        if (!infinite) {
          if (auto zero = function.zero_in_cell(probe, cell, p1, p2))
            return CGAL::make_object(*zero);
        }
        if (CGAL::sign(value) == CGAL::sign(v1)) {
          p1 = probe, v1 = value, c1 = cell, infinite1 = infinite;
        } else {
          p2 = probe, v2 = value, c2 = cell, infinite2 = infinite;
        }
      }
    }
  };

  // `count` points of the level: crossings of segments from the sphere's
  // centre (inside) to points on the sphere (outside), at fixed random
  // directions.
  class Construct_initial_points {
   public:
    template <typename Out>
    Out operator()(const ZeroLevel& level, Out out, int count = 20) const {
      if (level.seeds != nullptr && !level.seeds->empty())
        return std::copy(level.seeds->begin(), level.seeds->end(), out);
      CGAL::Random random(0);
      CGAL::Random_points_on_sphere_3<Point> on_sphere(std::sqrt(level.sphere.squared_radius()),
                                                       random);
      const Point& centre = level.sphere.center();
      const Intersect_3 intersect;
      // The centre is inside, so nearly every direction crosses; the bound
      // only keeps a degenerate function from looping.
      for (int tries = 0; count > 0 && tries < 100 * count; ++tries) {
        const Point far = centre + (*on_sphere++ - CGAL::ORIGIN);
        const auto hit = intersect(level, Segment_3(centre, far));
        if (const Point* point = CGAL::object_cast<Point>(&hit)) {
          *out++ = *point;
          --count;
        }
      }
      return out;
    }
  };

  Intersect_3 intersect_3_object() const { return {}; }
  Construct_initial_points construct_initial_points_object() const { return {}; }
};

}  // namespace labelmesh::surface::poisson
