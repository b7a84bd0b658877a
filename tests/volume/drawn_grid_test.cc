// SPDX-License-Identifier: AGPL-3.0-or-later
// The grid labels were drawn on: a segmentation resampled by nearest
// neighbour to finer pixels is found with its pitch and taken back to that
// grid voxel for voxel; native segmentations and slices drawn apart along
// one axis are left as they are.
#include "core/volume/drawn_grid.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>

#include "core/volume/label_statistics.h"
#include "core/volume/voxel_access.h"
#include "support/label_grid.h"
#include "support/status_matchers.h"

namespace labelmesh::volume {
namespace {

// Two nested ellipsoids (labels 2 and 7) and a ball beside them (label 4)
// drawn on `coarse` mm voxels, at grid index (i, j, k) of that grid.
uint8_t organs_at(int i, int j, int k) {
  const double x = i - 14.3, y = j - 12.6, z = k - 9.4;
  if (x * x / 25 + y * y / 16 + z * z / 9 < 1) return 7;
  if (x * x / 100 + y * y / 64 + z * z / 49 < 1) return 2;
  const double bx = x - 10, by = y + 6;
  return bx * bx + by * by + z * z < 9 ? 4 : 0;
}

// The organs on 3 mm voxels, 30 x 26 x 20 of them.
LabelVolume drawn_organs() { return testing::label_grid({30, 26, 20}, organs_at); }

// The same organs resampled by nearest neighbour to `pitch` times finer
// pixels along x and y (0.9766 mm for a pitch of 3.072, as a 3 mm
// segmentation stored on a CT's 512 x 512 grid).
LabelVolume resampled_organs(double pitch) {
  const int nx = static_cast<int>(30 * pitch), ny = static_cast<int>(26 * pitch);
  auto v = testing::label_grid({nx, ny, 20}, [pitch](int i, int j, int k) {
    const int ci = static_cast<int>(std::lround((i + 0.5) / pitch - 0.5));
    const int cj = static_cast<int>(std::lround((j + 0.5) / pitch - 0.5));
    return organs_at(ci, cj, k);
  });
  v.geometry.spacing = {3 / pitch, 3 / pitch, 3};
  return v;
}

std::map<int32_t, uint64_t> label_counts(const LabelVolume& v) {
  std::map<int32_t, uint64_t> counts;
  for (const auto& label : compute_label_statistics(v).labels) counts[label.label] = label.voxels;
  return counts;
}

TEST(DrawnGrid, PixelsResampledFromACoarserGridAreFoundWithTheirPitch) {
  for (double pitch : {3.072, 2.0, 4.0}) {
    const auto grid = find_drawn_grid(resampled_organs(pitch));
    EXPECT_TRUE(grid.resampled()) << pitch;
    EXPECT_NEAR(grid.axes[0].pitch, pitch, 0.01) << pitch;
    EXPECT_NEAR(grid.axes[1].pitch, pitch, 0.01) << pitch;
    EXPECT_EQ(grid.axes[2].pitch, 1) << pitch;
  }
}

TEST(DrawnGrid, TheDrawnGridGivesBackTheDrawnVoxels) {
  const auto fine = resampled_organs(3.072);
  const auto grid = find_drawn_grid(fine);
  ASSERT_TRUE(grid.resampled());
  auto drawn = resample_to_drawn_grid(fine, grid);
  ASSERT_THAT(drawn, testing::IsOk());
  const auto& g = drawn->geometry;
  // Any pitch that puts every change within half a voxel of the lattice
  // fits; the one found is within half a percent of the true one here.
  EXPECT_NEAR(g.spacing[0], 3, 0.015);
  EXPECT_NEAR(g.spacing[1], 3, 0.015);
  EXPECT_EQ(g.spacing[2], 3);
  EXPECT_EQ(g.dims[2], 20);
  // The drawn voxels' centres lie on the first grid's: whole voxels from
  // the fine grid's first edge, -0.5 fine voxels.
  for (int axis = 0; axis < 2; ++axis) {
    const double from_edge = (g.origin[axis] + 0.5 * fine.geometry.spacing[axis]) / 3;
    EXPECT_NEAR(from_edge - std::floor(from_edge), 0.5, 0.02) << axis;
  }
  EXPECT_EQ(label_counts(*drawn), label_counts(drawn_organs()));
}

TEST(DrawnGrid, ANativeSegmentationKeepsItsGrid) {
  const auto grid = find_drawn_grid(drawn_organs());
  EXPECT_FALSE(grid.resampled());
  for (const auto& axis : grid.axes) EXPECT_EQ(axis.pitch, 1);
}

TEST(DrawnGrid, SlicesDrawnApartAlongOneAxisAreNotAResampledImage) {
  // Every third slice drawn and copied: repeated planes, kept as they are.
  const auto v = testing::label_grid(
      {30, 26, 60}, [](int i, int j, int k) { return organs_at(i, j, (k + 1) / 3); });
  const auto grid = find_drawn_grid(v);
  EXPECT_NEAR(grid.axes[2].pitch, 3, 0.01);
  EXPECT_EQ(grid.axes[0].pitch, 1);
  EXPECT_FALSE(grid.resampled());
}

TEST(DrawnGrid, AFewFlatFacesAreNotALattice) {
  // A box 20 voxels wide: two changes per axis, too few to tell a grid.
  const auto v = testing::label_grid({40, 40, 40}, [](int i, int j, int k) -> uint8_t {
    return i >= 10 && i < 30 && j >= 10 && j < 30 && k >= 10 && k < 30 ? 1 : 0;
  });
  EXPECT_FALSE(find_drawn_grid(v).resampled());
}

}  // namespace
}  // namespace labelmesh::volume
