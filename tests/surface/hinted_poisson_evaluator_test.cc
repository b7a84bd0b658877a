// The surface mesher's evaluator of the Poisson function against CGAL's own
// evaluation of the same solved function.
#include "core/surface/hinted_poisson_evaluator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <CGAL/property_map.h>

namespace labelmesh::surface::poisson {
namespace {

using OrientedPoint = std::pair<Point, Vector>;

// Oriented points on a torus (ring radius 10, tube radius 4) around z.
std::vector<OrientedPoint> torus_points() {
  std::vector<OrientedPoint> points;
  constexpr int kAround = 90, kTube = 36;
  for (int i = 0; i < kAround; ++i) {
    const double u = 2 * std::numbers::pi * i / kAround;
    for (int j = 0; j < kTube; ++j) {
      const double v = 2 * std::numbers::pi * j / kTube;
      const Vector normal(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
      const Point centre(10 * std::cos(u), 10 * std::sin(u), 0);
      points.emplace_back(centre + 4 * normal, normal);
    }
  }
  return points;
}

class HintedPoissonEvaluatorTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(function_.compute_implicit_function());
    for (auto v = function_.tr().finite_vertices_begin(); v != function_.tr().finite_vertices_end();
         ++v)
      scale_ = std::max(scale_, std::abs(v->f()));
    ASSERT_GT(scale_, 0);
  }

  std::vector<OrientedPoint> points_ = torus_points();
  PoissonFunction function_{points_.begin(), points_.end(),
                            CGAL::First_of_pair_property_map<OrientedPoint>(),
                            CGAL::Second_of_pair_property_map<OrientedPoint>()};
  double scale_ = 0;
  RunContext context_;
};

TEST_F(HintedPoissonEvaluatorTest, GivesCgalsValueAndAContainingCell) {
  HintedEvaluator evaluator(function_, context_);
  const auto& tr = function_.tr();
  std::mt19937 random(7);
  // Inside the points' box, which CGAL's refinement keeps within the hull:
  // far jumps as the mesher makes them, then a bisection down to each.
  std::uniform_real_distribution<double> xy(-15, 15), z(-5, 5);
  int inside = 0;
  for (int jump = 0; jump < 2000; ++jump) {
    Point a(xy(random), xy(random), z(random));
    const Point b(xy(random), xy(random), z(random));
    for (int step = 0; step < 8; ++step, a = CGAL::midpoint(a, b)) {
      const auto [value, cell, infinite] = evaluator.evaluate(a);
      ASSERT_FALSE(infinite);
      EXPECT_NEAR(value, function_(a), 1e-9 * scale_);
      HintedEvaluator::Triangulation::Locate_type type;
      int i, j;
      EXPECT_NE(tr.side_of_cell(a, cell, type, i, j), CGAL::ON_UNBOUNDED_SIDE);
      inside += value < 0;
    }
  }
  // The queries did cross the surface: some fell inside the tube.
  EXPECT_GT(inside, 100);
  EXPECT_LT(inside, 15000);
}

TEST_F(HintedPoissonEvaluatorTest, RepeatedQuestionsGetTheSameAnswer) {
  HintedEvaluator evaluator(function_, context_);
  const Point p(10, 0, 3.9), q(-10, 0, -3.9);
  const auto first_p = evaluator.evaluate(p);
  const auto first_q = evaluator.evaluate(q);
  EXPECT_EQ(boost::get<0>(evaluator.evaluate(p)), boost::get<0>(first_p));
  EXPECT_EQ(boost::get<1>(evaluator.evaluate(q)), boost::get<1>(first_q));
  // Just inside the tube at both points: the function is negative inside.
  EXPECT_LT(boost::get<0>(first_p), 0);
  EXPECT_LT(boost::get<0>(first_q), 0);
}

TEST_F(HintedPoissonEvaluatorTest, StopsWhenAskedTo) {
  std::atomic<bool> stop{true};
  RunContext stopping;
  stopping.stop = &stop;
  HintedEvaluator evaluator(function_, stopping);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> xy(-15, 15);
  EXPECT_THROW(for (int i = 0; i < 10000; ++i) evaluator.evaluate(Point(xy(random), xy(random), 0)),
               Cancelled);
}

}  // namespace
}  // namespace labelmesh::surface::poisson
