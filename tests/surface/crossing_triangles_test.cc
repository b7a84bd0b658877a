// SPDX-License-Identifier: AGPL-3.0-or-later
// Crossing triangles of a soup: the same pairs CGAL's self-intersection test
// finds on a mesh, and the right ones where edges join three triangles.
#include "core/surface/crossing_triangles.h"

#include <gtest/gtest.h>

#include <random>

#include "core/surface/surface_checks.h"
#include "core/surface/triangle_mesh.h"
#include "support/lat_long_sphere.h"

namespace labelmesh::surface {
namespace {

TEST(CrossingTriangles, AgreesWithCgalOnAShakenSphere) {
  TriangleMesh m = testing::lat_long_sphere(24, 48);
  EXPECT_TRUE(crossing_triangles(m.points, m.triangles).empty());
  ASSERT_EQ(count_self_intersections(m), uint64_t{0});
  // Shake every point by up to 0.6 mm (edges are about 1.3 mm): folds and
  // crossings appear.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> shake(-0.6, 0.6);
  for (auto& p : m.points)
    for (double& c : p) c += shake(random);
  const auto pairs = crossing_triangles(m.points, m.triangles);
  const auto cgal = count_self_intersections(m);
  ASSERT_TRUE(cgal.has_value());
  EXPECT_GT(pairs.size(), 10u);
  EXPECT_EQ(pairs.size(), *cgal);
  for (const auto& [a, b] : pairs) EXPECT_LT(a, b);
}

TEST(CrossingTriangles, NearFindsThePairsOfTheGivenTriangles) {
  TriangleMesh m = testing::lat_long_sphere(24, 48);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> shake(-0.6, 0.6);
  for (auto& p : m.points)
    for (double& c : p) c += shake(random);
  const auto all = crossing_triangles(m.points, m.triangles);
  ASSERT_GT(all.size(), 10u);
  // Every third triangle of the first 600.
  std::vector<uint32_t> among;
  for (uint32_t t = 0; t < 600; t += 3) among.push_back(t);
  const auto in_among = [](uint32_t t) { return t < 600 && t % 3 == 0; };
  TrianglePairs expected;
  for (const auto& pair : all)
    if (in_among(pair.first) || in_among(pair.second)) expected.push_back(pair);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(crossing_triangles_near(m.points, m.triangles, among), expected);
}

TEST(CrossingTriangles, ThreeTrianglesOnOneEdge) {
  // The edge 0-1 on the x axis; triangle 0 rises along +z, 1 folds flat
  // onto it, 2 stands along +y, 3 lies far away and crosses nothing.
  const std::vector<std::array<double, 3>> points{{0, 0, 0},    {4, 0, 0},   {2, 0, 3},
                                                  {1, 0, 2},    {2, 3, 0},   {20, 20, 20},
                                                  {21, 20, 20}, {20, 21, 20}};
  const std::vector<std::array<uint32_t, 3>> triangles{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {5, 6, 7}};
  const auto pairs = crossing_triangles(points, triangles);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(uint32_t{0}, uint32_t{1}));
}

TEST(CrossingTriangles, ADegenerateTriangleIsPairedWithItself) {
  const std::vector<std::array<double, 3>> points{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
  const std::vector<std::array<uint32_t, 3>> triangles{{0, 1, 2}, {0, 1, 3}};
  const auto pairs = crossing_triangles(points, triangles);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(uint32_t{0}, uint32_t{0}));
}

}  // namespace
}  // namespace labelmesh::surface
