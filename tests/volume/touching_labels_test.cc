// SPDX-License-Identifier: AGPL-3.0-or-later
// Touching labels: the pairs whose voxels share faces, with exact counts.
#include "core/volume/touching_labels.h"

#include <gtest/gtest.h>

#include "support/label_grid.h"

namespace labelmesh::volume {
namespace {

// Box 1 is x 2..5 and box 2 x 6..8, both y and z 2..5: 16 faces meet. Label
// 3 sits apart; label 4 touches 2 along one voxel face and 1 only along an
// edge (which is not a face).
LabelVolume boxes() {
  return testing::label_grid({14, 8, 8}, [](int i, int j, int k) -> uint8_t {
    if (i == 1 && j == 1 && k == 3) return 4;  // an edge away from box 1
    if (i == 9 && j == 2 && k == 2) return 4;  // a face of box 2
    if (j < 2 || j > 5 || k < 2 || k > 5) return 0;
    if (i >= 2 && i <= 5) return 1;
    if (i >= 6 && i <= 8) return 2;
    return i >= 11 && i <= 12 ? 3 : 0;
  });
}

TEST(TouchingLabels, PairsAndTheirFacesCount) {
  const auto pairs = touching_labels(boxes(), {});
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].first, 1);
  EXPECT_EQ(pairs[0].second, 2);
  EXPECT_EQ(pairs[0].faces, 16u);
  EXPECT_EQ(pairs[1].first, 2);
  EXPECT_EQ(pairs[1].second, 4);
  EXPECT_EQ(pairs[1].faces, 1u);
}

TEST(TouchingLabels, OnlyTheSelectedLabelsCount) {
  const auto pairs = touching_labels(boxes(), {1, 3, 4});
  EXPECT_TRUE(pairs.empty());
  const auto two = touching_labels(boxes(), {2, 4});
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].faces, 1u);
}

}  // namespace
}  // namespace labelmesh::volume
