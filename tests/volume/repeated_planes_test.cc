// SPDX-License-Identifier: AGPL-3.0-or-later
// Runs of equal planes: a shape drawn on coarse slices and copied to finer
// ones is found with its copy count per axis, and nothing else is.
#include "core/volume/repeated_planes.h"

#include <gtest/gtest.h>

#include <array>

#include "core/volume/read_label_volume.h"
#include "support/label_grid.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume {
namespace {

std::array<int, 3> repeated_planes_of(const LabelVolume& v) {
  return find_repeated_planes(v, compute_label_statistics(v));
}

// A ball of radius 11 voxels (label 2) around a smaller one (label 5), drawn
// on planes `copies` apart along each axis and copied to the planes between.
LabelVolume coarse_ball(const std::array<int, 3>& copies) {
  return testing::label_grid({30, 28, 34}, [copies](int i, int j, int k) -> uint8_t {
    // Each voxel takes the value of the drawn plane below it (nearest
    // neighbour from coarse planes that start 1 voxel in, not on a multiple).
    // The centre is off the planes' midpoints: no two drawn planes mirror
    // each other, so neighbouring ones always differ.
    const double x = ((i + 1) / copies[0] * copies[0]) - 15.3;
    const double y = ((j + 1) / copies[1] * copies[1]) - 14.3;
    const double z = ((k + 1) / copies[2] * copies[2]) - 17.3;
    const double r2 = x * x + y * y + z * z;
    if (r2 < 16) return 5;
    return r2 < 121 ? 2 : 0;
  });
}

TEST(RepeatedPlanes, SlicesCopiedThreeTimesAreFound) {
  EXPECT_EQ(repeated_planes_of(coarse_ball({1, 1, 3})), (std::array<int, 3>{1, 1, 3}));
}

TEST(RepeatedPlanes, EachAxisIsFoundOnItsOwn) {
  EXPECT_EQ(repeated_planes_of(coarse_ball({2, 1, 4})), (std::array<int, 3>{2, 1, 4}));
  EXPECT_EQ(repeated_planes_of(coarse_ball({1, 3, 1})), (std::array<int, 3>{1, 3, 1}));
}

TEST(RepeatedPlanes, AShapeDrawnOnEveryPlaneRepeatsNone) {
  EXPECT_EQ(repeated_planes_of(coarse_ball({1, 1, 1})), (std::array<int, 3>{1, 1, 1}));
}

TEST(RepeatedPlanes, RunsOfMixedLengthsAreNotACopyCount) {
  // Planes copied 2, 3, 2, 3, ... times: no one length fits.
  const auto v = testing::label_grid({20, 20, 40}, [](int i, int j, int k) -> uint8_t {
    const int drawn = (k / 5) * 2 + (k % 5 >= 2 ? 1 : 0);  // runs 2, 3, 2, 3, ...
    const int half = 2 + drawn % 6;
    return (i >= 10 - half && i < 10 + half && j >= 4 && j < 16 && k >= 1) ? 1 : 0;
  });
  EXPECT_EQ(repeated_planes_of(v)[2], 1);
}

TEST(RepeatedPlanes, AnUnchangingPrismIsTooFewRunsToTell) {
  // A box: every plane across it is equal along each axis, one run each.
  const auto v = testing::label_grid({12, 12, 12}, [](int i, int j, int k) -> uint8_t {
    return (i >= 2 && i < 9 && j >= 3 && j < 10 && k >= 1 && k < 11) ? 1 : 0;
  });
  EXPECT_EQ(repeated_planes_of(v), (std::array<int, 3>{1, 1, 1}));
}

TEST(RepeatedPlanes, AnEmptyVolumeRepeatsNone) {
  const auto v = testing::label_grid({6, 6, 6}, [](int, int, int) -> uint8_t { return 0; });
  EXPECT_EQ(repeated_planes_of(v), (std::array<int, 3>{1, 1, 1}));
}

TEST(RepeatedPlanesRealData, TheLiverWasDrawnOnEveryThirdSlice) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  // 76 runs of exactly three equal slices: drawn at 2 mm, stored at 0.67 mm.
  auto liver = read_label_volume(testing::shared_data("liver.inr.gz"), ReadLimits{}, RunContext{});
  ASSERT_THAT(liver, testing::IsOk());
  EXPECT_EQ(repeated_planes_of(*liver), (std::array<int, 3>{1, 1, 3}));
  // Drawn on every 1.5 mm slice as stored.
  auto frog = read_label_volume(testing::shared_data("frogtissue.mhd"), ReadLimits{}, RunContext{});
  ASSERT_THAT(frog, testing::IsOk());
  EXPECT_EQ(repeated_planes_of(*frog), (std::array<int, 3>{1, 1, 1}));
}

}  // namespace
}  // namespace labelmesh::volume
