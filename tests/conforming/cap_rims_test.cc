// SPDX-License-Identifier: AGPL-3.0-or-later
// Which points of a cap's rim on the volume's edge are smoothed along the
// rim, on a hand-made stencil.
#include "core/conforming/cap_rims.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace labelmesh::conforming {
namespace {

constexpr uint8_t kZ = 1u << 2;   // pinned to a plane across z
constexpr uint8_t kXZ = 1u | kZ;  // a corner of the volume's box

Stencil stencil_of(const std::vector<std::vector<uint32_t>>& lists) {
  Stencil stencil;
  for (const auto& list : lists) {
    stencil.start.push_back(static_cast<uint32_t>(stencil.neighbours.size()));
    stencil.neighbours.insert(stencil.neighbours.end(), list.begin(), list.end());
  }
  stencil.start.push_back(static_cast<uint32_t>(stencil.neighbours.size()));
  stencil.along_curve.assign(lists.size(), false);
  return stencil;
}

std::vector<uint32_t> neighbours_of(const Stencil& stencil, uint32_t p) {
  return {stencil.neighbours.begin() + stencil.start[p],
          stencil.neighbours.begin() + stencil.start[p + 1]};
}

// Rim points 0 to 3 on the plane, in a row; 4 on the cap inside; 5 and 6 on
// the wall below; 7 a corner of the volume's box; 8 where three labels meet.
TEST(CapRims, OnlyRimPointsWithTwoRimNeighboursFollowTheRim) {
  const std::vector<std::vector<uint32_t>> lists{
      {1, 5}, {0, 2, 4, 5}, {1, 3, 4, 6}, {2, 6, 7, 8}, {1, 2}, {0, 1}, {2, 3}, {3}, {3, 6}};
  Stencil stencil = stencil_of(lists);
  PointBoxes boxes;
  boxes.pinned = {kZ, kZ, kZ, kZ, kZ, 0, 0, kXZ, kZ};
  const std::vector<uint8_t> label_count{2, 2, 2, 2, 2, 2, 2, 2, 3};
  EXPECT_EQ(follow_cap_rims(boxes, label_count, stencil), 2u);
  ASSERT_EQ(stencil.start.size(), lists.size() + 1);
  EXPECT_EQ(neighbours_of(stencil, 1), (std::vector<uint32_t>{0, 2}));
  EXPECT_EQ(neighbours_of(stencil, 2), (std::vector<uint32_t>{1, 3}));
  // The rim's ends (one rim neighbour: the corner and the junction do not
  // count), the cap, the wall, the corner and the junction keep theirs.
  for (const uint32_t p : {0u, 3u, 4u, 5u, 6u, 7u, 8u})
    EXPECT_EQ(neighbours_of(stencil, p), lists[p]) << p;
  EXPECT_EQ(stencil.neighbours.size(), stencil.start.back());
  for (size_t p = 0; p < lists.size(); ++p) EXPECT_FALSE(stencil.along_curve[p]) << p;
}

// Where three rims meet a point keeps all its neighbours; without pinned
// points nothing changes.
TEST(CapRims, ThreeRimNeighboursOrNoCapLeaveTheStencil) {
  const std::vector<std::vector<uint32_t>> lists{{1, 2, 3, 4}, {0, 4}, {0, 4}, {0, 4}, {0, 1}};
  Stencil stencil = stencil_of(lists);
  PointBoxes boxes;
  boxes.pinned = {kZ, kZ, kZ, kZ, 0};
  const std::vector<uint8_t> label_count(lists.size(), 2);
  EXPECT_EQ(follow_cap_rims(boxes, label_count, stencil), 0u);
  EXPECT_EQ(neighbours_of(stencil, 0), lists[0]);

  Stencil unpinned = stencil_of(lists);
  EXPECT_EQ(follow_cap_rims(PointBoxes{}, label_count, unpinned), 0u);
  EXPECT_EQ(unpinned.neighbours, stencil_of(lists).neighbours);
}

}  // namespace
}  // namespace labelmesh::conforming
