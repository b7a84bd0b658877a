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
  for (double pitch : {2.0, 2.2, 2.5, 3.072, 4.0, 5.5}) {
    const auto grid = find_drawn_grid(resampled_organs(pitch));
    EXPECT_TRUE(grid.resampled()) << pitch;
    EXPECT_NEAR(grid.axes[0].pitch, pitch, 0.015 * pitch) << pitch;
    EXPECT_NEAR(grid.axes[1].pitch, pitch, 0.015 * pitch) << pitch;
    EXPECT_EQ(grid.axes[2].pitch, 1) << pitch;
  }
}

// The drawn voxel holding a file voxel's centre along `axis`.
int64_t drawn_index(const DrawnAxis& axis, int64_t file) {
  return static_cast<int64_t>(std::floor((double(file) - axis.first_boundary) / axis.pitch));
}

TEST(DrawnGrid, TheDrawnGridGivesBackTheDrawnVoxels) {
  for (double pitch : {2.5, 3.072}) {
    const auto fine = resampled_organs(pitch);
    const auto grid = find_drawn_grid(fine);
    ASSERT_TRUE(grid.resampled());
    auto drawn = resample_to_drawn_grid(fine, grid);
    ASSERT_THAT(drawn, testing::IsOk());
    const auto& g = drawn->geometry;
    EXPECT_EQ(g.dims, (std::array<int64_t, 3>{30, 26, 20})) << pitch;
    EXPECT_NEAR(g.spacing[0], 3, 0.015 * 3) << pitch;
    EXPECT_EQ(g.spacing[2], 3);
    // The first drawn centre: half a drawn voxel from the fine grid's first
    // edge, half a fine voxel before its first centre; the changes tell it
    // to within half a fine voxel (they lie on whole fine voxels).
    const double first = 1.5 - 0.5 * fine.geometry.spacing[0];
    EXPECT_NEAR(g.origin[0], first, 0.5 * fine.geometry.spacing[0]) << pitch;
    EXPECT_NEAR(g.origin[1], first, 0.5 * fine.geometry.spacing[1]) << pitch;
    EXPECT_EQ(g.origin[2], 0);
    EXPECT_EQ(label_counts(*drawn), label_counts(drawn_organs())) << pitch;
    // Resampled back to the file's pixels, the drawn grid gives every
    // pixel its label.
    const auto* file_labels = static_cast<const uint8_t*>(fine.voxels->GetScalarPointer());
    const auto* drawn_labels = static_cast<const int32_t*>(drawn->voxels->GetScalarPointer());
    const auto& d = fine.geometry.dims;
    int64_t differing = 0;
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y)
        for (int64_t x = 0; x < d[0]; ++x) {
          const int64_t cx = drawn_index(grid.axes[0], x), cy = drawn_index(grid.axes[1], y);
          const int32_t back = drawn_labels[(z * g.dims[1] + cy) * g.dims[0] + cx];
          if (back != file_labels[(z * d[1] + y) * d[0] + x]) ++differing;
        }
    EXPECT_EQ(differing, 0) << pitch;
  }
}

// Labels that change at every drawn voxel (a 1.5 mm segmentation on 0.98
// mm pixels gives pitches under 2, where every boundary must show): 40 x 40
// x 6 drawn voxels of labels 0 to 3, resampled along x and y.
uint8_t patchwork_at(int i, int j, int k) {
  uint32_t h = static_cast<uint32_t>(i) * 73856093u + static_cast<uint32_t>(j) * 19349663u +
               static_cast<uint32_t>(k) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<uint8_t>(h % 4);
}

LabelVolume resampled_patchwork(double pitch) {
  const int n = static_cast<int>(40 * pitch);
  return testing::label_grid({n, n, 6}, [pitch](int i, int j, int k) {
    const int ci = static_cast<int>(std::lround((i + 0.5) / pitch - 0.5));
    const int cj = static_cast<int>(std::lround((j + 0.5) / pitch - 0.5));
    return patchwork_at(ci, cj, k);
  });
}

TEST(DrawnGrid, PitchesUnderTwoAreFoundWhereEveryBoundaryShows) {
  for (double pitch : {1.5, 1.536, 1.7, 1.9}) {
    const auto fine = resampled_patchwork(pitch);
    const auto grid = find_drawn_grid(fine);
    ASSERT_TRUE(grid.resampled()) << pitch;
    EXPECT_NEAR(grid.axes[0].pitch, pitch, 0.01 * pitch) << pitch;
    EXPECT_NEAR(grid.axes[1].pitch, pitch, 0.01 * pitch) << pitch;
    EXPECT_EQ(grid.axes[2].pitch, 1) << pitch;
    auto drawn = resample_to_drawn_grid(fine, grid);
    ASSERT_THAT(drawn, testing::IsOk());
    EXPECT_EQ(drawn->geometry.dims, (std::array<int64_t, 3>{40, 40, 6})) << pitch;
    const auto* labels = static_cast<const int32_t*>(drawn->voxels->GetScalarPointer());
    int64_t differing = 0;
    for (int k = 0; k < 6; ++k)
      for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i)
          if (labels[(k * 40 + j) * 40 + i] != patchwork_at(i, j, k)) ++differing;
    EXPECT_EQ(differing, 0) << pitch;
  }
  // The drawn patchwork itself changes at every plane: pitch 1.
  EXPECT_FALSE(find_drawn_grid(testing::label_grid({40, 40, 6}, patchwork_at)).resampled());
}

TEST(DrawnGrid, ASegmentOfFinerPixelsInAnotherLayerKeepsTheFileGrid) {
  auto v = resampled_organs(3.072);
  ASSERT_TRUE(find_drawn_grid(v).resampled());
  // An overlapping segment drawn on the fine pixels, kept in a layer.
  const auto& d = v.geometry.dims;
  const auto fine_ball =
      testing::label_grid({int(d[0]), int(d[1]), int(d[2])}, [](int i, int j, int k) -> uint8_t {
        const double x = i - 40.3, y = j - 37.6, z = k - 9.2;
        return x * x + y * y + 9 * z * z < 150 ? 9 : 0;
      });
  v.more_layers.push_back(fine_ball.voxels);
  EXPECT_FALSE(find_drawn_grid(v).resampled());
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
