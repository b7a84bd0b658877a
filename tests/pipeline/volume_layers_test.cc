// SPDX-License-Identifier: AGPL-3.0-or-later
// Overlapping segments kept in separate layers: each layer is a label volume
// of its own, and the statistics count every label once and the background
// as the voxels no layer labels.
#include "core/pipeline/volume_layers.h"

#include <gtest/gtest.h>

#include "support/label_grid.h"

namespace labelmesh {
namespace {

// Two 6x6x6 cubes in a 16^3 grid that share a 2x6x6 slab: label 1 at
// i in [2, 8), label 2 at i in [6, 12), in separate layers.
volume::LabelVolume overlapping_cubes() {
  auto inside = [](int lo, int i, int j, int k) {
    return i >= lo && i < lo + 6 && j >= 5 && j < 11 && k >= 5 && k < 11;
  };
  auto volume = testing::label_grid({16, 16, 16}, [&](int i, int j, int k) {
    return inside(2, i, j, k) ? uint8_t{1} : uint8_t{0};
  });
  const auto second = testing::label_grid({16, 16, 16}, [&](int i, int j, int k) {
    return inside(6, i, j, k) ? uint8_t{2} : uint8_t{0};
  });
  volume.more_layers.push_back(second.voxels);
  return volume;
}

TEST(VolumeLayers, EachLayerIsALabelVolumeOnTheSameGrid) {
  const auto volume = overlapping_cubes();
  const auto layers = volume_layers(volume);
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_TRUE(layers[0].more_layers.empty());
  EXPECT_EQ(layers[0].voxels, volume.voxels);
  EXPECT_EQ(layers[1].voxels, volume.more_layers[0]);
  EXPECT_EQ(layers[1].geometry.dims, volume.geometry.dims);
  const auto second = volume::compute_label_statistics(layers[1]);
  ASSERT_EQ(second.labels.size(), 1u);
  EXPECT_EQ(second.labels[0].label, 2);
}

TEST(VolumeLayers, StatisticsCountEveryLabelOnceAndTheUnionAsForeground) {
  const auto statistics = layered_statistics(volume_layers(overlapping_cubes()));
  ASSERT_EQ(statistics.labels.size(), 2u);
  EXPECT_EQ(statistics.labels[0].label, 1);
  EXPECT_EQ(statistics.labels[0].voxels, 216u);
  EXPECT_EQ(statistics.labels[1].label, 2);
  EXPECT_EQ(statistics.labels[1].voxels, 216u);
  EXPECT_EQ(statistics.labels[1].min_index, (std::array<int64_t, 3>{6, 5, 5}));
  // The union spans i in [2, 12): 10 x 6 x 6 voxels.
  EXPECT_EQ(statistics.background_voxels, 16u * 16 * 16 - 360);
}

TEST(VolumeLayers, OneLayerIsTheVolumeItself) {
  auto volume = overlapping_cubes();
  volume.more_layers.clear();
  const auto layers = volume_layers(volume);
  ASSERT_EQ(layers.size(), 1u);
  const auto statistics = layered_statistics(layers);
  const auto direct = volume::compute_label_statistics(volume);
  ASSERT_EQ(statistics.labels.size(), direct.labels.size());
  EXPECT_EQ(statistics.background_voxels, direct.background_voxels);
}

}  // namespace
}  // namespace labelmesh
