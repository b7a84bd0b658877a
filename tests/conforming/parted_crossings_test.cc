// SPDX-License-Identifier: AGPL-3.0-or-later
// Crossing pairs of faces parted across a gap, and the voxels around them.
#include "core/conforming/parted_crossings.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace labelmesh::conforming {
namespace {

// Three triangles in a padded box of 6 x 5 x 4 voxels starting at volume
// index (-1, 2, 0): label 1 against the outside, label 2 against the
// outside, label 1 against label 2. Only their sides and side voxels matter.
InterfaceSurface three_faces() {
  InterfaceSurface net;
  net.padded_dims = {6, 5, 4};
  net.padded_first = {-1, 2, 0};
  // Volume voxel (x, y, z) as a linear index into the padded box.
  const auto padded = [&](int64_t x, int64_t y, int64_t z) {
    return static_cast<uint64_t>((z * 5 + (y - 2)) * 6 + (x + 1));
  };
  net.sides = {{1, kOutside}, {kOutside, 2}, {1, 2}};
  net.side_voxels = {{padded(1, 3, 1), padded(2, 3, 1)},
                     {padded(2, 3, 1), padded(2, 4, 2)},
                     {padded(0, 2, 0), padded(0, 2, 1)}};
  return net;
}

TEST(PartedCrossings, OnlyPairsSharingTheOutsideAloneCount) {
  const auto net = three_faces();
  EXPECT_TRUE(shares_only_outside(net, 0, 1));
  EXPECT_FALSE(shares_only_outside(net, 0, 2));  // label 1 on both
  EXPECT_FALSE(shares_only_outside(net, 1, 2));  // label 2 on both
}

TEST(PartedCrossings, VoxelsAroundTheCrossingFacesWithinTheVolume) {
  const auto net = three_faces();
  const std::array<int64_t, 3> dims{8, 7, 6};
  const auto index = [&](int64_t x, int64_t y, int64_t z) {
    return static_cast<uint64_t>((z * dims[1] + y) * dims[0] + x);
  };
  // Reach 0: the three distinct side voxels of triangles 0 and 1.
  EXPECT_EQ(voxels_near_parted_crossings(net, {{0, 1}}, dims, 0),
            (std::vector<uint64_t>{index(1, 3, 1), index(2, 3, 1), index(2, 4, 2)}));
  // A pair that shares a label adds nothing.
  EXPECT_TRUE(voxels_near_parted_crossings(net, {{0, 2}}, dims, 1).empty());
  // Reach 1: the voxels of the 3 x 3 x 3 cubes around those three.
  std::vector<uint64_t> expected;
  for (const auto& [x, y, z] : std::vector<std::array<int64_t, 3>>{{1, 3, 1}, {2, 3, 1}, {2, 4, 2}})
    for (int64_t k = z - 1; k <= z + 1; ++k)
      for (int64_t j = y - 1; j <= y + 1; ++j)
        for (int64_t i = x - 1; i <= x + 1; ++i) expected.push_back(index(i, j, k));
  std::sort(expected.begin(), expected.end());
  expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
  EXPECT_EQ(voxels_near_parted_crossings(net, {{0, 1}}, dims, 1), expected);
  // Clipped to a volume of 2 x 4 x 2 voxels: the 8 at x 0..1, y 2..3.
  EXPECT_EQ(voxels_near_parted_crossings(net, {{0, 1}}, {2, 4, 2}, 1).size(), 2u * 2u * 2u);
}

}  // namespace
}  // namespace labelmesh::conforming
