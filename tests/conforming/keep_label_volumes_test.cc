// SPDX-License-Identifier: AGPL-3.0-or-later
// Giving labels back their volume: two unit cubes side by side, label 1
// and label 2, the outside around them; label 1's far face pushed in.
#include "core/conforming/keep_label_volumes.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "core/conforming/interface_surface.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// Point (x, y, z) of the two cubes' twelve corners, x from 0 to 2.
uint32_t corner(int x, int y, int z) { return static_cast<uint32_t>(x * 4 + y * 2 + z); }

struct TwoCubes {
  std::vector<Vec3> centre;
  std::vector<std::array<uint32_t, 4>> quads;
  std::vector<std::array<int32_t, 2>> sides;
};

// Each quad wound so that its normal points from sides[0] into sides[1].
TwoCubes two_cubes() {
  TwoCubes c;
  for (int x = 0; x <= 2; ++x)
    for (int y = 0; y <= 1; ++y)
      for (int z = 0; z <= 1; ++z) c.centre.push_back({double(x), double(y), double(z)});
  for (int label = 1; label <= 2; ++label) {
    const int x0 = label - 1, x1 = label;
    // The four walls around the x axis, outward.
    c.quads.push_back({corner(x0, 0, 0), corner(x1, 0, 0), corner(x1, 0, 1), corner(x0, 0, 1)});
    c.quads.push_back({corner(x0, 1, 0), corner(x0, 1, 1), corner(x1, 1, 1), corner(x1, 1, 0)});
    c.quads.push_back({corner(x0, 0, 0), corner(x0, 1, 0), corner(x1, 1, 0), corner(x1, 0, 0)});
    c.quads.push_back({corner(x0, 0, 1), corner(x1, 0, 1), corner(x1, 1, 1), corner(x0, 1, 1)});
    for (int k = 0; k < 4; ++k) c.sides.push_back({label, kOutside});
  }
  // The ends: label 1's at x = 0 facing -x, label 2's at x = 2 facing +x,
  // and the face between them from label 1 into label 2.
  c.quads.push_back({corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0)});
  c.sides.push_back({1, kOutside});
  c.quads.push_back({corner(2, 0, 0), corner(2, 1, 0), corner(2, 1, 1), corner(2, 0, 1)});
  c.sides.push_back({2, kOutside});
  c.quads.push_back({corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), corner(1, 0, 1)});
  c.sides.push_back({1, 2});
  return c;
}

// The volume `label` encloses with its quads at `x`.
double volume_of(const TwoCubes& c, const std::vector<Vec3>& x, int32_t label) {
  double volume = 0;
  for (size_t q = 0; q < c.quads.size(); ++q) {
    const auto& k = c.quads[q];
    const double v = (geometry::dot(x[k[0]], geometry::cross(x[k[1]], x[k[2]])) +
                      geometry::dot(x[k[0]], geometry::cross(x[k[2]], x[k[3]]))) /
                     6;
    if (c.sides[q][0] == label) volume += v;
    if (c.sides[q][1] == label) volume -= v;
  }
  return volume;
}

PointBoxes boxes_of_half(double half) {
  PointBoxes boxes;
  boxes.half = {half, half, half};
  return boxes;
}

TEST(KeepLabelVolumes, APushedInFaceComesBackAndTheOtherLabelStays) {
  const TwoCubes c = two_cubes();
  ASSERT_NEAR(volume_of(c, c.centre, 1), 1.0, 1e-12);
  ASSERT_NEAR(volume_of(c, c.centre, 2), 1.0, 1e-12);
  std::vector<Vec3> points = c.centre;
  for (int y = 0; y <= 1; ++y)
    for (int z = 0; z <= 1; ++z) points[corner(0, y, z)][0] = 0.2;
  ASSERT_NEAR(volume_of(c, points, 1), 0.8, 1e-12);
  const LabelVolumeKeeper keeper(c.quads, c.sides, std::vector<bool>(c.centre.size(), false),
                                 c.centre);
  keeper.restore(boxes_of_half(0.45), kVolumeRounds, points);
  EXPECT_NEAR(volume_of(c, points, 1), 1.0, 0.01);
  // Points where label 1, label 2 and the outside meet stay; label 2 lost
  // nothing, so its points stay too.
  for (int x = 1; x <= 2; ++x)
    for (int y = 0; y <= 1; ++y)
      for (int z = 0; z <= 1; ++z)
        EXPECT_EQ(points[corner(x, y, z)], c.centre[corner(x, y, z)]) << x << y << z;
}

TEST(KeepLabelVolumes, HeldPointsAndBoxesHold) {
  const TwoCubes c = two_cubes();
  std::vector<Vec3> points = c.centre;
  for (int y = 0; y <= 1; ++y)
    for (int z = 0; z <= 1; ++z) points[corner(0, y, z)][0] = 0.2;
  std::vector<bool> held(c.centre.size(), false);
  held[corner(0, 0, 0)] = true;
  const LabelVolumeKeeper keeper(c.quads, c.sides, held, c.centre);
  // Boxes of a tenth: the face can come back only to x = 0.1.
  keeper.restore(boxes_of_half(0.1), kVolumeRounds, points);
  EXPECT_EQ(points[corner(0, 0, 0)][0], 0.2);
  for (const auto [y, z] : {std::array<int, 2>{0, 1}, {1, 0}, {1, 1}}) {
    EXPECT_GE(points[corner(0, y, z)][0], -0.1);
    EXPECT_LE(points[corner(0, y, z)][0], 0.1 + 1e-12);
  }
  EXPECT_LT(volume_of(c, points, 1), 1.0);
  EXPECT_GT(volume_of(c, points, 1), 0.8);
}

}  // namespace
}  // namespace labelmesh::conforming
