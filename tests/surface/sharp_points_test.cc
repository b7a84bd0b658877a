// SPDX-License-Identifier: AGPL-3.0-or-later
// The bench's count of sharp points: tips and saddles, not rims.
#include "support/sharp_points.h"

#include <gtest/gtest.h>

#include "support/lat_long_sphere.h"

namespace labelmesh::testing {
namespace {

TEST(SharpPoints, AnOctahedronsCornersAreSharpAFineSphereHasNone) {
  // Four triangles of 60 degrees meet at each corner: 2 pi / 3 short of a turn.
  const auto octahedron = lat_long_sphere(2, 4);
  ASSERT_EQ(octahedron.points.size(), 6u);
  EXPECT_EQ(sharp_points(octahedron, 2.0).sharp, 6u);
  EXPECT_EQ(sharp_points(octahedron, 2.2).sharp, 0u);
  const auto fine = lat_long_sphere(40, 80);
  const auto counted = sharp_points(fine, 0.1);
  EXPECT_EQ(counted.points, fine.points.size());
  EXPECT_EQ(counted.sharp, 0u);
}

TEST(SharpPoints, PointsOnAnOpenRimAreLeftOut) {
  // A low pyramid without its base: its four corners lie on the open rim.
  surface::TriangleMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0.1}};
  m.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const auto counted = sharp_points(m, 0.01);
  EXPECT_EQ(counted.points, 1u);
  EXPECT_EQ(counted.sharp, 1u);
  EXPECT_EQ(sharp_points(m, 0.5).sharp, 0u);
}

}  // namespace
}  // namespace labelmesh::testing
