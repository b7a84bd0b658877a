// SPDX-License-Identifier: AGPL-3.0-or-later
// The box of accepted voxels: tight on every side, empty when none is.
#include "core/volume/voxel_box.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

namespace labelmesh::volume {
namespace {

constexpr std::array<int64_t, 3> kDims{7, 5, 6};

std::vector<int16_t> empty_grid() { return std::vector<int16_t>(7 * 5 * 6, 0); }

void set(std::vector<int16_t>& grid, int64_t x, int64_t y, int64_t z, int16_t label) {
  grid[static_cast<size_t>((z * kDims[1] + y) * kDims[0] + x)] = label;
}

TEST(VoxelBox, HoldsTheAcceptedVoxelsTightly) {
  auto grid = empty_grid();
  set(grid, 2, 1, 4, 3);
  set(grid, 5, 3, 1, 3);
  set(grid, 6, 4, 5, 9);  // not accepted: only label 3 counts
  const auto box = voxel_box(grid.data(), kDims, [](int16_t v) { return v == 3; });
  ASSERT_FALSE(box.empty());
  EXPECT_EQ(box.first, (std::array<int64_t, 3>{2, 1, 1}));
  EXPECT_EQ(box.last, (std::array<int64_t, 3>{5, 3, 4}));
}

TEST(VoxelBox, ReachesTheGridsCorners) {
  auto grid = empty_grid();
  set(grid, 0, 0, 0, -2);
  set(grid, 6, 4, 5, 1);
  const auto box = voxel_box(grid.data(), kDims, [](int16_t v) { return v != 0; });
  EXPECT_EQ(box.first, (std::array<int64_t, 3>{0, 0, 0}));
  EXPECT_EQ(box.last, (std::array<int64_t, 3>{6, 4, 5}));
}

TEST(VoxelBox, IsEmptyWithoutAnAcceptedVoxel) {
  const auto grid = empty_grid();
  EXPECT_TRUE(voxel_box(grid.data(), kDims, [](int16_t v) { return v != 0; }).empty());
  EXPECT_TRUE(voxel_box(grid.data(), {0, 0, 0}, [](int16_t) { return true; }).empty());
}

}  // namespace
}  // namespace labelmesh::volume
