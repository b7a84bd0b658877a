// SPDX-License-Identifier: AGPL-3.0-or-later
// Crossing pairs of faces parted across a gap, and the voxels around them.
#include "core/conforming/parted_crossings.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace labelmesh::conforming {
namespace {

// Three triangles in a padded box of 6 x 5 x 4 voxels starting at volume
// index (-1, -1, -1): label 1 against the outside, label 2 against the
// outside, label 1 against label 2. Only their sides and side voxels matter.
InterfaceSurface three_faces() {
  InterfaceSurface net;
  net.padded_dims = {6, 5, 4};
  net.padded_first = {-1, -1, -1};
  const auto padded = [&](int64_t x, int64_t y, int64_t z) {
    return static_cast<uint64_t>(((z + 1) * 5 + (y + 1)) * 6 + (x + 1));
  };
  net.sides = {{1, kOutside}, {kOutside, 2}, {1, 2}};
  net.side_voxels = {{padded(1, 1, 1), padded(2, 1, 1)},
                     {padded(2, 1, 1), padded(3, 1, 1)},
                     {padded(0, 0, 0), padded(0, 0, 1)}};
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
  const std::array<int64_t, 3> dims{4, 3, 2};
  const auto index = [&](int64_t x, int64_t y, int64_t z) {
    return static_cast<uint64_t>((z * dims[1] + y) * dims[0] + x);
  };
  // Reach 0: the three distinct side voxels of triangles 0 and 1.
  EXPECT_EQ(voxels_near_parted_crossings(net, {{0, 1}}, dims, 0),
            (std::vector<uint64_t>{index(1, 1, 1), index(2, 1, 1), index(3, 1, 1)}));
  // A pair that shares a label adds nothing.
  EXPECT_TRUE(voxels_near_parted_crossings(net, {{0, 2}}, dims, 1).empty());
  // Reach 1 from x = 1..3 at y = 1, z = 1: x 0..3, y 0..2, z 0..1, clipped
  // to the volume: all 24 of its voxels.
  const auto around = voxels_near_parted_crossings(net, {{0, 1}}, dims, 1);
  EXPECT_EQ(around.size(), 24u);
  EXPECT_TRUE(std::is_sorted(around.begin(), around.end()));
}

}  // namespace
}  // namespace labelmesh::conforming
