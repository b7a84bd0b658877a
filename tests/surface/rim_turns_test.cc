// SPDX-License-Identifier: AGPL-3.0-or-later
// The bench's measure of how sharply the rims of caps on the volume's edge
// turn, on prisms whose top lies on the edge.
#include "support/rim_turns.h"

#include <gtest/gtest.h>

#include <cmath>

namespace labelmesh::testing {
namespace {

// A prism over a regular polygon of `corners` about (5, 5), radius 3, from
// z = 7.5 up to `top`, closed by a fan at each end.
surface::TriangleMesh prism(int corners, double top) {
  surface::TriangleMesh m;
  const auto n = static_cast<uint32_t>(corners);
  for (const double z : {top, 7.5}) {
    for (uint32_t k = 0; k < n; ++k) {
      const double a = 2 * M_PI * k / n;
      m.points.push_back({5 + 3 * std::cos(a), 5 + 3 * std::sin(a), z});
    }
  }
  m.points.push_back({5, 5, top});
  m.points.push_back({5, 5, 7.5});
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t next = (k + 1) % n;
    m.triangles.push_back({2 * n, k, next});
    m.triangles.push_back({2 * n + 1, n + next, n + k});
    m.triangles.push_back({k, n + k, n + next});
    m.triangles.push_back({k, n + next, next});
  }
  return m;
}

volume::ImageGeometry ten_voxels() {
  volume::ImageGeometry geometry;
  geometry.dims = {10, 10, 10};  // the top edge at z = 9.5
  return geometry;
}

TEST(RimTurns, EachRimPointOfAPolygonalCapTurnsByItsOuterAngle) {
  for (const int corners : {4, 8, 16}) {
    RimTurns turns;
    add_rim_turns(prism(corners, 9.5), ten_voxels(), turns);
    EXPECT_EQ(turns.points, size_t(corners)) << corners;
    EXPECT_NEAR(turns.sum_deg / double(turns.points), 360.0 / corners, 1e-9) << corners;
    EXPECT_EQ(turns.over_30_deg, corners < 12 ? size_t(corners) : 0u) << corners;
  }
}

TEST(RimTurns, AShapeOffTheEdgeHasNoRim) {
  RimTurns turns;
  add_rim_turns(prism(8, 9.0), ten_voxels(), turns);
  EXPECT_EQ(turns.points, 0u);
}

}  // namespace
}  // namespace labelmesh::testing
