// SPDX-License-Identifier: AGPL-3.0-or-later
// The Poisson solve's own assembly against CGAL's: a torus solved through
// CGAL's generic solve_poisson and through labelmesh's specialisation gives
// the same function at every vertex of the same triangulation.
#include "core/surface/poisson/poisson_linear_system.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <CGAL/property_map.h>

#include "core/surface/poisson/hinted_poisson_evaluator.h"
#include "tests/support/solved_torus.h"

namespace labelmesh::testing {
namespace {

using surface::poisson::CancellableSolver;

// A function of `points` with its triangulation built, not yet solved.
PoissonFunction unsolved(const std::vector<std::pair<Point, Vector>>& points) {
  using OrientedPoint = std::pair<Point, Vector>;
  return PoissonFunction(points.begin(), points.end(),
                         CGAL::First_of_pair_property_map<OrientedPoint>(),
                         CGAL::Second_of_pair_property_map<OrientedPoint>());
}

// Solved by labelmesh's assembly; the fixture's function_ by CGAL's.
class PoissonLinearSystemTest : public SolvedTorusTest {
 protected:
  PoissonFunction ours_ = unsolved(points_);
};

// The torus's points moved by up to 0.1 in each coordinate: no longer
// cocircular, so every cell has a well-defined circumcentre and CGAL's
// weights do not depend on which end of an edge they were taken from.
std::vector<std::pair<Point, Vector>> jittered_torus_points() {
  auto points = torus_points();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> offset(-0.1, 0.1);
  for (auto& [point, normal] : points)
    point = point + Vector(offset(random), offset(random), offset(random));
  return points;
}

TEST_F(PoissonLinearSystemTest, GivesCgalsFunctionWhereItsWeightsAreDefined) {
  const auto points = jittered_torus_points();
  PoissonFunction cgal = unsolved(points), mine = unsolved(points);
  // CGAL's own solve_poisson, with its default Eigen solver.
  ASSERT_TRUE(cgal.compute_implicit_function());
  int iterations = 0;
  // Tight enough that the two solves' own stopping points do not matter.
  ASSERT_TRUE(mine.compute_implicit_function(CancellableSolver(&context_, 1e-12, &iterations)));
  // Only labelmesh's solver counts iterations: the specialisation ran.
  EXPECT_GT(iterations, 10);

  ASSERT_EQ(mine.tr().number_of_vertices(), cgal.tr().number_of_vertices());
  double scale = 0, largest_difference = 0;
  size_t vertices = 0;
  for (auto a = cgal.tr().finite_vertices_begin(), b = mine.tr().finite_vertices_begin();
       a != cgal.tr().finite_vertices_end(); ++a, ++b, ++vertices) {
    ASSERT_EQ(a->point(), b->point());
    scale = std::max(scale, std::abs(a->f()));
    largest_difference = std::max(largest_difference, std::abs(a->f() - b->f()));
  }
  EXPECT_GT(vertices, points.size());  // the refinement's Steiner points too
  EXPECT_GT(scale, 1);
  EXPECT_LT(largest_difference, 1e-8 * scale);
  EXPECT_EQ(mine.get_inner_point(), cgal.get_inner_point());
}

TEST_F(PoissonLinearSystemTest, KeepsTheSurfaceOfCocircularPoints) {
  // The parametric torus's cocircular points are where CGAL's weights
  // depend on the end an edge was weighed from: the functions then differ,
  // but both put the tube's centre circle inside and the ring's hole and
  // the far outside outside, as far from their level as CGAL's.
  int iterations = 0;
  ASSERT_TRUE(ours_.compute_implicit_function(CancellableSolver(&context_, 1e-12, &iterations)));
  auto value = [](const PoissonFunction& f, const Point& p) {
    // The mean of the cell's finite vertices' values is enough to tell the
    // sides apart this far from the level; CGAL's evaluator is not used on
    // a function labelmesh solved (its cache is not filled).
    const auto cell = f.tr().locate(p);
    double sum = 0;
    int finite = 0;
    for (int i = 0; i < 4; ++i) {
      if (f.tr().is_infinite(cell->vertex(i))) continue;
      sum += cell->vertex(i)->f();
      ++finite;
    }
    return sum / finite;
  };
  for (int i = 0; i < 12; ++i) {
    const double u = 2 * std::numbers::pi * i / 12;
    const Point centre(10 * std::cos(u), 10 * std::sin(u), 0);
    EXPECT_LT(value(ours_, centre), -0.1 * scale_) << "tube centre at " << u;
    EXPECT_LT(value(function_, centre), -0.1 * scale_);
  }
  EXPECT_GT(value(ours_, Point(0, 0, 0)), 0.1 * scale_);
  EXPECT_GT(value(ours_, Point(0, 0, 12)), 0.1 * scale_);
}

TEST_F(PoissonLinearSystemTest, ALooseToleranceStopsEarlierNearTheSameFunction) {
  int tight = 0, loose = 0;
  ASSERT_TRUE(ours_.compute_implicit_function(CancellableSolver(&context_, 1e-12, &tight)));
  std::vector<double> tight_values;
  for (auto v = ours_.tr().finite_vertices_begin(); v != ours_.tr().finite_vertices_end(); ++v)
    tight_values.push_back(v->f());

  PoissonFunction again = unsolved(points_);
  ASSERT_TRUE(again.compute_implicit_function(CancellableSolver(&context_, 1e-3, &loose)));
  EXPECT_LT(loose, tight);
  double largest_difference = 0;
  size_t i = 0;
  for (auto v = again.tr().finite_vertices_begin(); v != again.tr().finite_vertices_end(); ++v)
    largest_difference = std::max(largest_difference, std::abs(v->f() - tight_values[i++]));
  EXPECT_GT(largest_difference, 0);
  EXPECT_LT(largest_difference, 0.05 * scale_);
}

// The unknowns are numbered along a Hilbert curve: every vertex but the
// constrained one, once each, in that order, so that the ends of an edge (a
// matrix entry) are numbered far closer together than in the
// triangulation's memory order.
TEST_F(PoissonLinearSystemTest, NumbersTheUnknownsAlongAHilbertCurve) {
  int iterations = 0;
  ASSERT_TRUE(ours_.compute_implicit_function(CancellableSolver(&context_, 1e-6, &iterations)));
  const auto& tr = ours_.tr();
  const auto curve = surface::poisson::along_hilbert_curve(tr);
  ASSERT_EQ(curve.size(), tr.number_of_vertices() - 1);
  for (size_t i = 0; i < curve.size(); ++i) {
    ASSERT_FALSE(tr.is_constrained(curve[i]));
    ASSERT_EQ(curve[i]->index(), int(i));  // the assembly's rows, in this order
  }
  std::map<PoissonFunction::Triangulation::Vertex_handle, int> in_memory;
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v) {
    if (!tr.is_constrained(v)) in_memory.emplace(v, int(in_memory.size()));
  }
  // The median gap between the numbers of an edge's ends.
  auto median_gap = [&](auto number) {
    std::vector<int> gaps;
    for (auto e = tr.finite_edges_begin(); e != tr.finite_edges_end(); ++e) {
      const auto v = e->first->vertex(e->second), w = e->first->vertex(e->third);
      if (tr.is_constrained(v) || tr.is_constrained(w)) continue;
      gaps.push_back(std::abs(number(v) - number(w)));
    }
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    return gaps[gaps.size() / 2];
  };
  const int along_curve = median_gap([](auto v) { return int(v->index()); });
  const int by_memory = median_gap([&](auto v) { return in_memory.at(v); });
  EXPECT_LT(along_curve, by_memory / 4);
}

}  // namespace
}  // namespace labelmesh::testing
