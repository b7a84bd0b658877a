// SPDX-License-Identifier: AGPL-3.0-or-later
// The sheets through one voxel cube: parted only where two labels lie a
// voxel apart with outside between them.
#include "core/conforming/cube_sheets.h"

#include <gtest/gtest.h>

namespace labelmesh::conforming {
namespace {

// Corner k lies at offsets k & 1, (k >> 1) & 1, k >> 2.
TEST(CubeSheets, TwoLabelsMeetOnOneSheet) {
  const auto s = cube_sheets({1, 1, 1, 1, 0, 0, 0, 0});
  EXPECT_EQ(s.pair_count, 1);
  EXPECT_EQ(s.sheet_count, 1);
  EXPECT_EQ(s.labels[0], 2);
  EXPECT_EQ(s.sheet_of(0, 1), 0);
  EXPECT_EQ(s.sheet_of(1, 0), 0);
  EXPECT_EQ(s.sheet_of(1, 2), -1);
}

TEST(CubeSheets, LabelsAVoxelApartAcrossOutsidePart) {
  // Label 1 at one corner, label 2 at the opposite one, outside between.
  const auto s = cube_sheets({1, 0, 0, 0, 0, 0, 0, 2});
  EXPECT_EQ(s.pair_count, 2);
  EXPECT_EQ(s.sheet_count, 2);
  EXPECT_NE(s.sheet_of(0, 1), s.sheet_of(0, 2));
  EXPECT_EQ(s.labels[0], 2);
  EXPECT_EQ(s.labels[1], 2);
}

TEST(CubeSheets, LabelsThatTouchMeetTheOutsideOnOneJunction) {
  // Labels 1 and 2 face neighbours along the first axis, outside above.
  const auto s = cube_sheets({1, 2, 1, 2, 0, 0, 0, 0});
  EXPECT_EQ(s.pair_count, 3);
  EXPECT_EQ(s.sheet_count, 1);
  EXPECT_EQ(s.labels[0], 3);
}

TEST(CubeSheets, BothFacesOfALabelStayOnePiece) {
  // Label 1 fills the lower layer; above it label 2 at one corner and
  // outside at the others: label 1's surface passes from one to the other.
  const auto s = cube_sheets({1, 1, 1, 1, 0, 0, 0, 2});
  EXPECT_EQ(s.sheet_count, 1);
  // Two labels a voxel apart across a third label are not parted either.
  const auto across = cube_sheets({1, 3, 3, 3, 3, 3, 3, 2});
  EXPECT_EQ(across.pair_count, 2);
  EXPECT_EQ(across.sheet_count, 1);
}

}  // namespace
}  // namespace labelmesh::conforming
