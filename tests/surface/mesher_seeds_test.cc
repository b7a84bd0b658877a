// SPDX-License-Identifier: AGPL-3.0-or-later
// The surface mesher's seeds on a solved torus: on the zero level, spread
// over all of it, no two near each other, and what the oracle hands the mesher.
#include "core/surface/poisson/mesher_seeds.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <vector>

#include "support/solved_torus.h"

namespace labelmesh::surface::poisson {
namespace {

using MesherSeedsTest = testing::SolvedTorusTest;

constexpr double kSpacing = 2;  // mm; the torus's points are about 0.7 mm apart
constexpr double kReach = 1;

ZeroLevel torus_level(const SolvedFunction& function) {
  return {&function, Kernel::Sphere_3(Point(10, 0, 0), 100 * 100), 1e-6};
}

double nearest(const Point& p, const std::vector<Point>& among) {
  double best = std::numeric_limits<double>::max();
  for (const Point& q : among) {
    if (q != p) best = std::min(best, CGAL::squared_distance(p, q));
  }
  return std::sqrt(best);
}

TEST_F(MesherSeedsTest, SeedsLieOnTheLevelAndSpreadOverIt) {
  HintedEvaluator evaluator(function_, context_);
  const SolvedFunction function(&evaluator);
  const auto seeds = mesher_seeds(torus_level(function), points_, kSpacing, kReach);
  // The torus's area (4 pi^2 * 10 * 4 = 1579 mm^2) over a disc of the
  // spacing's radius packs at most about 126 seeds; a greedy packing keeps
  // well over a third of that.
  EXPECT_GT(seeds.size(), 60u);
  EXPECT_LT(seeds.size(), 2 * 1579 / (kSpacing * kSpacing));
  for (const Point& seed : seeds) {
    EXPECT_LT(std::abs(function_(seed)), 1e-9 * scale_);
    // Thinned to the spacing, then moved by much less than the reach.
    EXPECT_GT(nearest(seed, seeds), 0.75 * kSpacing);
  }
  // Every point of the torus has a seed within the spacing (and the move).
  for (const auto& [point, normal] : points_) EXPECT_LT(nearest(point, seeds), kSpacing + 0.25);
  // Deterministic: the same seeds again, from an evaluator with another past.
  HintedEvaluator other(function_, context_);
  const SolvedFunction again(&other);
  EXPECT_EQ(mesher_seeds(torus_level(again), points_, kSpacing, kReach), seeds);
}

TEST_F(MesherSeedsTest, PointsFartherThanTheReachFromTheLevelGiveNone) {
  HintedEvaluator evaluator(function_, context_);
  const SolvedFunction function(&evaluator);
  // Every point 3 mm out along its normal: the level is beyond a 1 mm reach,
  // and within a 4 mm one.
  auto moved = points_;
  for (auto& [point, normal] : moved) point = point + 3 * normal;
  EXPECT_TRUE(mesher_seeds(torus_level(function), moved, kSpacing, kReach).empty());
  const auto seeds = mesher_seeds(torus_level(function), moved, kSpacing, 4);
  EXPECT_GT(seeds.size(), 60u);
  for (const Point& seed : seeds) EXPECT_LT(std::abs(function_(seed)), 1e-9 * scale_);
}

TEST_F(MesherSeedsTest, AFarPointWidensTheCubesInsteadOfAllocatingBillions) {
  HintedEvaluator evaluator(function_, context_);
  const SolvedFunction function(&evaluator);
  // One point 10 km away in x and y makes the box 10 km wide and 8 mm thin:
  // at 0.01 mm cubes that would be 10^18 of them, and cubes sized by the
  // box's volume alone 7 * 10^8 (3 GB of them).
  auto points = points_;
  points.emplace_back(Point(1e7, 1e7, 0), Vector(1, 0, 0));
  const auto seeds = mesher_seeds(torus_level(function), points, 0.01, kReach);
  // Thinned to 0.01 mm, every torus point near the level is its own seed.
  EXPECT_GT(seeds.size(), points_.size() / 2);
  for (const Point& seed : seeds) EXPECT_LT(std::abs(function_(seed)), 1e-9 * scale_);
}

TEST_F(MesherSeedsTest, TheOracleStartsTheMesherFromTheSeeds) {
  HintedEvaluator evaluator(function_, context_);
  const SolvedFunction function(&evaluator);
  ZeroLevel level = torus_level(function);
  const auto seeds = mesher_seeds(level, points_, kSpacing, kReach);
  level.seeds = &seeds;
  std::vector<Point> initial;
  ZeroLevelOracle().construct_initial_points_object()(level, std::back_inserter(initial), 20);
  EXPECT_EQ(initial, seeds);
}

}  // namespace
}  // namespace labelmesh::surface::poisson
