// SPDX-License-Identifier: AGPL-3.0-or-later
// A CGAL Poisson function solved from oriented points on a torus (ring radius
// 10, tube radius 4, around z): negative inside the tube, positive outside.
#pragma once

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <CGAL/property_map.h>

#include "core/surface/poisson/hinted_poisson_evaluator.h"

namespace labelmesh::testing {

using surface::poisson::Point;
using surface::poisson::PoissonFunction;
using surface::poisson::Vector;

inline std::vector<std::pair<Point, Vector>> torus_points() {
  std::vector<std::pair<Point, Vector>> points;
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

// Solves once per test; `scale_` is the largest |value| at a vertex.
class SolvedTorusTest : public ::testing::Test {
 protected:
  using OrientedPoint = std::pair<Point, Vector>;

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

}  // namespace labelmesh::testing
