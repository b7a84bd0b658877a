// SPDX-License-Identifier: AGPL-3.0-or-later
// The surface mesher's evaluator of the Poisson function against CGAL's own
// evaluation of the same solved function.
#include "core/surface/poisson/hinted_poisson_evaluator.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "support/solved_torus.h"

namespace labelmesh::surface::poisson {
namespace {

using HintedPoissonEvaluatorTest = testing::SolvedTorusTest;

TEST_F(HintedPoissonEvaluatorTest, GivesCgalsValueAndAContainingCell) {
  HintedEvaluator evaluator(function_, context_);
  const auto& tr = function_.tr();
  std::mt19937 random(7);
  // Far jumps as the mesher makes them, then a bisection down to each; twice
  // over the same targets, so the second pass walks from the grid's cells.
  // The box is a little larger than the torus's, inside CGAL's refinement.
  std::uniform_real_distribution<double> xy(-15, 15), z(-5, 5);
  std::vector<std::pair<Point, Point>> jumps;
  for (int jump = 0; jump < 2000; ++jump) {
    jumps.emplace_back(Point(xy(random), xy(random), z(random)),
                       Point(xy(random), xy(random), z(random)));
  }
  int inside = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (auto [a, b] : jumps) {
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
  }
  // The queries did cross the surface: some fell inside the tube.
  EXPECT_GT(inside, 200);
  EXPECT_LT(inside, 30000);
}

TEST_F(HintedPoissonEvaluatorTest, OutsideTheHullGivesAHullVertexValue) {
  // The mesher's ball is five times the points' radius; CGAL refines to 1.5.
  HintedEvaluator evaluator(function_, context_);
  const auto& tr = function_.tr();
  for (int k = 0; k < 200; ++k) {
    const double angle = 0.1 * k;
    const Point far(60 * std::cos(angle), 60 * std::sin(angle), 20 * std::sin(3 * angle));
    const auto [value, cell, infinite] = evaluator.evaluate(far);
    const auto cgal = function_.special_func(far);
    ASSERT_TRUE(infinite);
    EXPECT_TRUE(boost::get<2>(cgal));
    EXPECT_TRUE(tr.is_infinite(cell));
    bool from_a_vertex = false;
    for (int v = 0; v < 4; ++v) {
      if (!tr.is_infinite(cell->vertex(v))) from_a_vertex |= cell->vertex(v)->f() == value;
    }
    EXPECT_TRUE(from_a_vertex);
    // Far outside, the function is positive, as CGAL's is.
    EXPECT_GT(value, 0);
    EXPECT_GT(boost::get<0>(cgal), 0);
  }
}

TEST_F(HintedPoissonEvaluatorTest, RepeatedQuestionsGetCgalsAnswer) {
  HintedEvaluator evaluator(function_, context_);
  const Point p(10, 0, 3.9), q(-10, 0, -3.9);
  for (int round = 0; round < 3; ++round) {
    for (const Point& point : {p, q}) {
      const auto answer = evaluator.evaluate(point);
      const auto cgal = function_.special_func(point);
      EXPECT_NEAR(boost::get<0>(answer), boost::get<0>(cgal), 1e-9 * scale_);
      // Just inside the tube: the function is negative inside.
      EXPECT_LT(boost::get<0>(answer), 0);
    }
  }
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

// CGAL's refinement and assembly have no callback: a stop reaches them
// through the kernel's squared-distance functor, while a SolveScope marks the
// thread. Neither the visitor nor the solver here looks for a stop.
TEST(StopAwareKernel, AStopEndsASolveWithNoCallbackOfItsOwn) {
  const auto points = testing::torus_points();
  using OrientedPoint = std::pair<Point, Vector>;
  auto make_function = [&] {
    return std::make_unique<PoissonFunction>(points.begin(), points.end(),
                                             CGAL::First_of_pair_property_map<OrientedPoint>(),
                                             CGAL::Second_of_pair_property_map<OrientedPoint>());
  };
  std::atomic<bool> stop{true};
  RunContext stopping;
  stopping.stop = &stop;
  {
    const auto function = make_function();
    const SolveScope scope(stopping);
    EXPECT_THROW(function->compute_implicit_function(), Cancelled);
  }
  // The scope is gone: the same stop no longer reaches CGAL.
  EXPECT_EQ(solving_run, nullptr);
  const auto function = make_function();
  EXPECT_TRUE(function->compute_implicit_function());
  EXPECT_LT(function->operator()(Point(10, 0, 0)), 0);  // inside the tube
  EXPECT_GT(function->operator()(Point(0, 0, 0)), 0);   // in the ring's hole
}

}  // namespace
}  // namespace labelmesh::surface::poisson
