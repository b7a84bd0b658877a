// SPDX-License-Identifier: AGPL-3.0-or-later
// The bench's count of sharp points: tips and saddles, not rims.
#include "support/sharp_points.h"

#include <gtest/gtest.h>

#include <cmath>

namespace labelmesh::testing {
namespace {

// A closed sphere of radius 10 from a longitude-latitude grid.
surface::TriangleMesh sphere(int rings, int segments) {
  surface::TriangleMesh m;
  m.points.push_back({0, 0, 10});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / segments;
      m.points.push_back({10 * std::sin(theta) * std::cos(phi),
                          10 * std::sin(theta) * std::sin(phi), 10 * std::cos(theta)});
    }
  m.points.push_back({0, 0, -10});
  const auto at = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + s % segments); };
  const auto south = uint32_t(m.points.size() - 1);
  for (int s = 0; s < segments; ++s) {
    m.triangles.push_back({0, at(1, s), at(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      m.triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
    m.triangles.push_back({at(rings - 1, s), south, at(rings - 1, s + 1)});
  }
  return m;
}

TEST(SharpPoints, AnOctahedronsCornersAreSharpAFineSphereHasNone) {
  // Four triangles of 60 degrees meet at each corner: 2 pi / 3 short of a turn.
  const auto octahedron = sphere(2, 4);
  ASSERT_EQ(octahedron.points.size(), 6u);
  EXPECT_EQ(sharp_points(octahedron, 2.0).sharp, 6u);
  EXPECT_EQ(sharp_points(octahedron, 2.2).sharp, 0u);
  const auto fine = sphere(40, 80);
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
