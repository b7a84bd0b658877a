// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/surface_statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace labelmesh::surface {
namespace {

// Unit right-corner tetrahedron, outward.
TriangleMesh tetrahedron(double shift = 0) {
  TriangleMesh m;
  m.points = {{shift, 0, 0}, {shift + 1, 0, 0}, {shift, 1, 0}, {shift, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

TEST(SurfaceStatistics, Tetrahedron) {
  const auto s = compute_surface_statistics(tetrahedron());
  EXPECT_EQ(s.nodes, 4u);
  EXPECT_EQ(s.triangles, 4u);
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_EQ(s.components, 1u);
  EXPECT_NEAR(s.volume_mm3, 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.min_angle_deg, 45.0, 1e-9);
  EXPECT_NEAR(s.max_angle_deg, 90.0, 1e-9);
  EXPECT_EQ(s.triangles_below_30_deg, 0u);
  EXPECT_NEAR(s.area_mm2, 1.5 + std::sqrt(3.0) / 2, 1e-12);
}

TEST(SurfaceStatistics, InsideOutHasNegativeVolume) {
  auto m = tetrahedron();
  m.flip_orientation();
  EXPECT_NEAR(compute_surface_statistics(m).volume_mm3, -1.0 / 6.0, 1e-12);
}

TEST(SurfaceStatistics, MissingTriangleLeavesThreeBoundaryEdges) {
  auto m = tetrahedron();
  m.triangles.pop_back();
  const auto s = compute_surface_statistics(m);
  EXPECT_FALSE(s.closed);
  EXPECT_EQ(s.boundary_edges, 3u);
  EXPECT_EQ(s.euler_characteristic, 1);
  EXPECT_TRUE(s.manifold);
}

TEST(SurfaceStatistics, FinOnAnEdgeIsNonManifold) {
  auto m = tetrahedron();
  m.points.push_back({0.5, -1, 0});
  m.triangles.push_back({0, 1, 4});
  const auto s = compute_surface_statistics(m);
  EXPECT_EQ(s.non_manifold_edges, 1u);
  EXPECT_FALSE(s.manifold);
}

// Two tetrahedra touching at one vertex.
TriangleMesh bowtie() {
  auto m = tetrahedron();
  const auto other = tetrahedron(-1);  // its vertex 1 is (0,0,0) = our vertex 0
  const uint32_t base = static_cast<uint32_t>(m.points.size());
  for (const auto& p : other.points) m.points.push_back(p);
  for (auto t : other.triangles) {
    for (auto& v : t) v = v == 1 ? 0 : v + base;
    m.triangles.push_back(t);
  }
  return m;
}

TEST(SurfaceStatistics, TwoTetrahedraSharingAVertexMakeABowtie) {
  const auto s = compute_surface_statistics(bowtie());
  EXPECT_EQ(s.non_manifold_vertices, 1u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_FALSE(s.manifold);
  EXPECT_EQ(s.components, 1u);
}

TEST(SurfaceStatistics, OrientedManifoldNeedsOneWindingAndOneFanPerPoint) {
  EXPECT_TRUE(is_oriented_manifold(tetrahedron()));
  auto open = tetrahedron();
  open.triangles.pop_back();
  EXPECT_TRUE(is_oriented_manifold(open));  // a boundary is allowed
  auto flipped = tetrahedron();
  std::swap(flipped.triangles[3][0], flipped.triangles[3][1]);
  EXPECT_FALSE(is_oriented_manifold(flipped));
  auto fin = tetrahedron();
  fin.points.push_back({0.5, -1, 0});
  fin.triangles.push_back({1, 0, 4});
  EXPECT_FALSE(is_oriented_manifold(fin));
  EXPECT_FALSE(is_oriented_manifold(bowtie()));
  auto degenerate = tetrahedron();
  degenerate.triangles.push_back({2, 3, 2});
  EXPECT_FALSE(is_oriented_manifold(degenerate));
}

TEST(SurfaceStatistics, OneTriangleTurnedOverIsNotWoundAlike) {
  EXPECT_TRUE(compute_surface_statistics(tetrahedron()).consistently_wound);
  auto inside_out = tetrahedron();
  inside_out.flip_orientation();
  EXPECT_TRUE(compute_surface_statistics(inside_out).consistently_wound);
  // Still closed and manifold.
  auto turned = tetrahedron();
  std::swap(turned.triangles[0][1], turned.triangles[0][2]);
  const auto s = compute_surface_statistics(turned);
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_FALSE(s.consistently_wound);
}

TEST(SurfaceStatistics, SliverTriangleAngles) {
  TriangleMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0.5, 1e-3, 0}};
  m.triangles = {{0, 1, 2}};
  const auto s = compute_surface_statistics(m);
  EXPECT_LT(s.min_angle_deg, 0.2);
  EXPECT_GT(s.max_angle_deg, 179.5);
}

// A triangle whose apex sits h above the middle of a unit base has base
// angles atan(2 h): below 30 degrees for h < 0.2887.
TEST(SurfaceStatistics, CountsTrianglesWithAnAngleBelowThirtyDegrees) {
  TriangleMesh m;
  for (const double h : {0.25, 0.28, 0.29, 0.5, 0.87}) {
    const auto base = static_cast<uint32_t>(m.points.size());
    m.points.push_back({0, 0, 3 * h});
    m.points.push_back({1, 0, 3 * h});
    m.points.push_back({0.5, h, 3 * h});
    m.triangles.push_back({base, base + 1, base + 2});
  }
  EXPECT_EQ(compute_surface_statistics(m).triangles_below_30_deg, 2u);
}

}  // namespace
}  // namespace labelmesh::surface
