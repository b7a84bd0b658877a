// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/thick_slices.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/conforming/check_conforming_mesh.h"
#include "core/conforming/conforming_mesher.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom_grid.h"
#include "core/volume/voxel_access.h"
#include "support/analytic_shapes.h"
#include "support/label_volumes.h"
#include "support/organs_on_slices.h"
#include "support/status_matchers.h"

namespace labelmesh::conforming {
namespace {

using testing::label_volumes;
const std::array<double, 3> kCentre{10, -20, 30};
constexpr double kInner = 8, kOuter = 16;  // mm

// Label 1 inside a ball of radius kInner, 2 in the shell out to kOuter.
int32_t nested_label(const std::array<double, 3>& p) {
  const double d = geometry::norm(geometry::sub(p, kCentre));
  return d < kInner ? 1 : d < kOuter ? 2 : 0;
}

// The nested balls on 0.5 x 0.5 x 3 mm voxels (slices along z, or along
// `thick_axis`).
volume::LabelVolume thick_nested_balls(int thick_axis = 2) {
  std::array<double, 3> spacing{0.5, 0.5, 0.5};
  spacing[thick_axis] = 3;
  std::array<int64_t, 3> dims{};
  for (int a = 0; a < 3; ++a) dims[a] = static_cast<int64_t>(std::ceil(36 / spacing[a])) + 1;
  return volume::rasterise(
      volume::centred_grid(dims, spacing, testing::kIdentityDirection, kCentre), nested_label);
}

std::vector<int32_t> labels_of(const volume::LabelVolume& volume) {
  std::vector<int32_t> out;
  volume::visit_voxels(
      volume.voxels, [&](const auto* voxels, size_t count) { out.assign(voxels, voxels + count); });
  return out;
}

// The thinner grid's labels over the whole field of view, x fastest: the
// interpolation covers the labels' box, and every thin voxel beyond it is 0.
std::vector<int32_t> whole_thin_labels(const volume::LabelVolume& fine,
                                       const volume::LabelVolume& thick, const ThickSlices& cut) {
  volume::ImageGeometry whole = thick.geometry;
  whole.dims[cut.axis] *= cut.parts;
  whole.spacing[cut.axis] /= cut.parts;
  std::array<double, 3> first{0, 0, 0};
  first[cut.axis] = -0.5 + 0.5 / cut.parts;
  whole.origin = thick.geometry.to_physical(first);
  const auto at = whole.to_index(fine.geometry.origin);
  std::array<int64_t, 3> offset{};
  for (int k = 0; k < 3; ++k) {
    offset[k] = std::llround(at[k]);
    // The box starts on a voxel of the whole thinner grid.
    EXPECT_NEAR(at[k], double(offset[k]), 1e-6) << "axis " << k;
    EXPECT_GE(offset[k], 0);
    EXPECT_LE(offset[k] + fine.geometry.dims[k], whole.dims[k]);
  }
  const auto& d = whole.dims;
  std::vector<int32_t> labels(static_cast<size_t>(d[0] * d[1] * d[2]), 0);
  const auto part = labels_of(fine);
  const auto& b = fine.geometry.dims;
  size_t i = 0;
  for (int64_t z = 0; z < b[2]; ++z)
    for (int64_t y = 0; y < b[1]; ++y)
      for (int64_t x = 0; x < b[0]; ++x, ++i)
        labels[static_cast<size_t>(((z + offset[2]) * d[1] + y + offset[1]) * d[0] + x +
                                   offset[0])] = part[i];
  return labels;
}

// The centre (LPS mm) of `label`'s voxels in `volume`.
std::array<double, 3> label_centre(const volume::LabelVolume& volume, int32_t label) {
  const auto labels = labels_of(volume);
  const auto& d = volume.geometry.dims;
  std::array<double, 3> sum{0, 0, 0};
  size_t count = 0, i = 0;
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y)
      for (int64_t x = 0; x < d[0]; ++x, ++i) {
        if (labels[i] != label) continue;
        sum = geometry::add(sum, volume.geometry.to_physical({double(x), double(y), double(z)}));
        ++count;
      }
  return geometry::scale(sum, 1.0 / double(std::max<size_t>(count, 1)));
}

volume::LabelVolume interpolated(const volume::LabelVolume& thick, const ThickSlices& cut) {
  auto fine = interpolate_thick_slices(thick, {}, cut, RunContext{});
  EXPECT_THAT(fine, testing::IsOk());
  return fine.ok() ? std::move(*fine) : volume::LabelVolume{};
}

TEST(ThickSlices, FindsTheThickAxisAndHowFineToCutIt) {
  volume::ImageGeometry g;
  g.dims = {100, 100, 20};
  g.spacing = {0.5, 0.5, 3};
  EXPECT_EQ(find_thick_slices(g, {}).axis, 2);
  EXPECT_EQ(find_thick_slices(g, {}).parts, 3);
  g.spacing = {3, 0.55, 0.5};
  EXPECT_EQ(find_thick_slices(g, {}).axis, 0);
  EXPECT_EQ(find_thick_slices(g, {}).parts, 3);  // 3 / (2 x 0.55), rounded
  g.spacing = {0.6, 0.6, 2};
  EXPECT_EQ(find_thick_slices(g, {}).parts, 2);
  g.spacing = {1, 1, 2.5};  // not thick enough to cut
  EXPECT_EQ(find_thick_slices(g, {}).axis, -1);
  g.spacing = {0.2, 0.2, 10};
  EXPECT_EQ(find_thick_slices(g, {}).parts, 8);  // at most max_parts
  ThickSliceParams small;
  small.max_voxels = g.voxel_count() * 5;
  EXPECT_EQ(find_thick_slices(g, small).parts, 5);  // no more voxels than a volume may hold
  small.max_voxels = g.voxel_count();
  EXPECT_EQ(find_thick_slices(g, small).axis, -1);
}

// A small label in a wide field of view (a vertebra on 0.34 mm pixels and
// 1 mm slices): the thinner voxels are counted over the labels' box, which
// the interpolation covers, so the cut is made where the whole field of
// view would have been too many voxels for it.
TEST(ThickSlices, ThinVoxelsAreCountedOverTheLabelsBox) {
  const auto thick =
      volume::rasterise(volume::centred_grid({400, 400, 60}, {0.34375, 0.34375, 1},
                                             testing::kIdentityDirection, kCentre),
                        [](const std::array<double, 3>& p) {
                          return geometry::norm(geometry::sub(p, kCentre)) < 8 ? 1 : 0;
                        });
  // As the surface nets cut: from a ratio of 2.5, as thin as the pixels.
  ThickSliceParams params;
  params.min_ratio = 2.5;
  params.thin_ratio = 1;
  params.max_voxels = 10'000'000;  // the whole view cut in 3 would be 28.8 million
  EXPECT_EQ(find_thick_slices(thick.geometry, params).axis, -1);
  const ThickSlices cut = find_thick_slices(thick, {}, params);
  ASSERT_EQ(cut.axis, 2);
  ASSERT_EQ(cut.parts, 3);
  const auto fine = interpolated(thick, cut);
  // The ball's box (47 pixels and 17 slices across) with its margins.
  const auto& d = fine.geometry.dims;
  EXPECT_LT(d[0] * d[1] * d[2], int64_t{1'000'000});
  EXPECT_EQ(d[2] % 3, 0);
  // Every voxel of the ball is in it, and the volume is the ball's.
  EXPECT_NEAR(label_volumes(fine).at(1) / label_volumes(thick).at(1), 1.0, 0.01);
  // Placed where the ball is: its thin voxels' centre on the drawn ones'
  // (a box a thin voxel off would move it by a third of a millimetre).
  EXPECT_LT(geometry::norm(geometry::sub(label_centre(fine, 1), label_centre(thick, 1))), 0.1);
  (void)whole_thin_labels(fine, thick, cut);  // checks the box lies on the whole grid
}

// The same on an oblique grid whose thick axis is x: the box's origin
// follows the grid's directions along every axis.
TEST(ThickSlices, AnObliqueBoxAlongXIsPlacedWhereItsLabelIs) {
  const double c = std::cos(25 * M_PI / 180), s = std::sin(25 * M_PI / 180);
  const std::array<double, 9> turned{c, -s, 0, s, c, 0, 0, 0, 1};
  const auto thick = volume::rasterise(
      volume::centred_grid({60, 300, 300}, {1, 0.34375, 0.34375}, turned, kCentre),
      [](const std::array<double, 3>& p) {
        return geometry::norm(geometry::sub(p, geometry::add(kCentre, {3, -4, 5}))) < 8 ? 1 : 0;
      });
  ThickSliceParams params;
  params.min_ratio = 2.5;
  params.thin_ratio = 1;
  params.max_voxels = 10'000'000;
  const ThickSlices cut = find_thick_slices(thick, {}, params);
  ASSERT_EQ(cut.axis, 0);
  ASSERT_EQ(cut.parts, 3);
  const auto fine = interpolated(thick, cut);
  EXPECT_LT(fine.geometry.dims[1] * fine.geometry.dims[2], 300 * 300 / 4);
  EXPECT_NEAR(label_volumes(fine).at(1) / label_volumes(thick).at(1), 1.0, 0.01);
  EXPECT_LT(geometry::norm(geometry::sub(label_centre(fine, 1), label_centre(thick, 1))), 0.1);
  (void)whole_thin_labels(fine, thick, cut);
}

TEST(ThickSlices, RefuseACutThatIsNotOne) {
  const auto thick = thick_nested_balls();
  for (const ThickSlices cut : {ThickSlices{2, 1}, ThickSlices{3, 2}, ThickSlices{-1, 2}}) {
    const auto fine = interpolate_thick_slices(thick, {}, cut, RunContext{});
    EXPECT_THAT(fine, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  }
}

// A label two pixels wide on one slice alone: interpolation alone would lose
// it between slices; the bias brings its volume back.
TEST(ThickSlices, ALabelOnOneSliceKeepsItsVolume) {
  const std::array<double, 3> spacing{0.6, 0.6, 2.4};
  const auto grid =
      volume::centred_grid({40, 40, 5}, spacing, testing::kIdentityDirection, kCentre);
  const auto thick = volume::rasterise(grid, [&](const std::array<double, 3>& p) {
    const auto index = grid.to_index(p);
    const bool on_slice = std::lround(index[2]) == 2;
    const bool stripe = std::lround(index[0]) >= 19 && std::lround(index[0]) <= 20 &&
                        std::lround(index[1]) >= 5 && std::lround(index[1]) <= 34;
    return on_slice && stripe ? 7 : std::lround(index[1]) < 20 ? 1 : 0;
  });
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  ASSERT_EQ(cut.parts, 2);
  const auto fine = interpolated(thick, cut);
  const auto thick_volumes = label_volumes(thick);
  const auto fine_volumes = label_volumes(fine);
  ASSERT_TRUE(fine_volumes.contains(7));
  EXPECT_NEAR(fine_volumes.at(7) / thick_volumes.at(7), 1.0, 0.02);
  // Within the 1 % the bias aims at.
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
}

TEST(ThickSlices, KeepEachSliceAndEachLabelsVolume) {
  const auto thick = thick_nested_balls();
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  ASSERT_EQ(cut.axis, 2);
  ASSERT_EQ(cut.parts, 3);
  const auto fine = interpolated(thick, cut);
  EXPECT_EQ(fine.geometry.dims[2], thick.geometry.dims[2] * 3);
  EXPECT_DOUBLE_EQ(fine.geometry.spacing[2], 1.0);
  // Both grids start and end at the same plane.
  const auto first_thick = thick.geometry.to_physical({0, 0, -0.5});
  const auto first_fine = fine.geometry.to_physical({0, 0, -0.5});
  EXPECT_NEAR(geometry::norm(geometry::sub(first_thick, first_fine)), 0, 1e-9);

  const auto thick_volumes = label_volumes(thick);
  const auto fine_volumes = label_volumes(fine);
  ASSERT_EQ(fine_volumes.size(), 2u);
  // Both within the 1 % the bias aims at (the inner ball, of 8,600 thin
  // voxels, gains or loses them 60-70 at a time).
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
  EXPECT_NEAR(fine_volumes.at(2) / thick_volumes.at(2), 1.0, 0.01);
}

// Five organs that grow and meet from slice to slice: every thin voxel
// holds the label of the drawn voxel below or above its pixel, however the
// labels' distances compete or the cubic overshoots between slices.
TEST(ThickSlices, AThinVoxelTakesALabelItsPixelIsDrawnWith) {
  const auto thick = testing::five_organs_on_three_slices();
  ThickSliceParams params;
  params.min_ratio = 2.5;
  params.thin_ratio = 1;
  const ThickSlices cut = find_thick_slices(thick.geometry, params);
  ASSERT_EQ(cut.axis, 2);
  ASSERT_GE(cut.parts, 4);
  const auto fine = interpolated(thick, cut);
  const auto drawn = labels_of(thick);
  const auto thin = whole_thin_labels(fine, thick, cut);
  const auto& dims = thick.geometry.dims;
  const int64_t plane = dims[0] * dims[1];
  ASSERT_EQ(thin.size(), static_cast<size_t>(plane * dims[2] * cut.parts));
  size_t foreign = 0, between = 0;
  for (int64_t j = 0; j < dims[2] * cut.parts; ++j) {
    const double position =
        std::clamp((j + 0.5) / cut.parts - 0.5, 0.0, static_cast<double>(dims[2] - 1));
    const int64_t below = std::min<int64_t>(static_cast<int64_t>(position), dims[2] - 2);
    for (int64_t p = 0; p < plane; ++p) {
      const int32_t label = thin[static_cast<size_t>(j * plane + p)];
      const int32_t under = drawn[static_cast<size_t>(below * plane + p)];
      const int32_t over = drawn[static_cast<size_t>((below + 1) * plane + p)];
      if (label != under && label != over) ++foreign;
      if (under != over) ++between;
    }
  }
  EXPECT_EQ(foreign, 0u);
  // The organs do change between slices: the test has pixels to fail on.
  EXPECT_GT(between, 10'000u);
}

TEST(ThickSlices, FollowTheShapeBetweenSlicesBetterThanTheSlicesDo) {
  const auto thick = thick_nested_balls();
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  const auto fine = interpolated(thick, cut);
  const auto fine_labels = labels_of(fine);
  const auto thick_labels = labels_of(thick);
  const auto& d = fine.geometry.dims;
  size_t interpolated_wrong = 0, sliced_wrong = 0;
  size_t i = 0;
  for (int64_t z = 0; z < d[2]; ++z) {
    for (int64_t y = 0; y < d[1]; ++y) {
      for (int64_t x = 0; x < d[0]; ++x, ++i) {
        const int32_t truth =
            nested_label(fine.geometry.to_physical({double(x), double(y), double(z)}));
        interpolated_wrong += fine_labels[i] != truth;
        // The thick voxel this fine one lies in.
        const auto at =
            thick.geometry.to_index(fine.geometry.to_physical({double(x), double(y), double(z)}));
        const auto& t = thick.geometry.dims;
        const auto index = [&](int k) { return std::llround(at[k]); };
        sliced_wrong +=
            thick_labels[static_cast<size_t>((index(2) * t[1] + index(1)) * t[0] + index(0))] !=
            truth;
      }
    }
  }
  EXPECT_GT(sliced_wrong, 3000u);
  EXPECT_LT(interpolated_wrong, sliced_wrong / 2);
}

// A ring whose volume the bias restores (in a run of this phantom its thin
// slices lost 4 % before it, and an unfaded bias moved edges on the drawn
// slices): the bias acts between drawn slices only,
// so each thin slice through a drawn slice's centre holds that slice's labels voxel for voxel, and
// the voxel centres the surface is judged by stay as they were drawn.
TEST(ThickSlices, DrawnSlicesKeepTheirVoxelsWhileTheBiasRestoresVolume) {
  const auto ring = testing::torus_shape(25, 9);
  const auto thick = testing::sample_shape(ring, {0.6, 0.6, 4});
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  ASSERT_EQ(cut.axis, 2);
  ASSERT_EQ(cut.parts, 3);
  const auto fine = interpolated(thick, cut);
  const auto drawn = labels_of(thick);
  const auto thin = whole_thin_labels(fine, thick, cut);
  ASSERT_EQ(thin.size(), drawn.size() * static_cast<size_t>(cut.parts));
  const auto& dims = thick.geometry.dims;
  const int64_t plane = dims[0] * dims[1];
  size_t changed = 0;
  for (int64_t slice = 0; slice < dims[2]; ++slice) {
    const int64_t centre = slice * cut.parts + cut.parts / 2;
    for (int64_t p = 0; p < plane; ++p) {
      changed += thin[static_cast<size_t>(centre * plane + p)] !=
                 drawn[static_cast<size_t>(slice * plane + p)];
    }
  }
  EXPECT_EQ(changed, 0u);
  const auto thick_volumes = label_volumes(thick);
  const auto fine_volumes = label_volumes(fine);
  // Within the 1 % the bias aims at.
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
}

// A tube 9 mm across whose top and bottom lie exactly on drawn slices'
// centres, so two drawn slices hold it and each ends a whole slice short of
// the next: its interpolated ends round off before the next slice, and the
// bias must swell its walls by more than a slice to give the volume back
// (a bias held to one slice left it 7 % short).
TEST(ThickSlices, ATubeTwoSlicesThickKeepsItsVolume) {
  const auto tube = testing::torus_shape(25, 4.5);
  const auto thick = testing::sample_shape(tube, {1, 1, 3}, 0, 0.5);
  const auto& grid = thick.geometry;
  // Cut as the surface nets cut: into slices as thin as the pixels.
  ThickSliceParams as_for_surfaces;
  as_for_surfaces.thin_ratio = 1;
  const ThickSlices cut = find_thick_slices(thick.geometry, as_for_surfaces);
  ASSERT_EQ(cut.axis, 2);
  ASSERT_EQ(cut.parts, 3);
  const auto thick_volumes = label_volumes(thick);
  ASSERT_TRUE(thick_volumes.contains(1));
  // Two slices, 1.5 mm below and above the tube's middle, hold it.
  const auto drawn = labels_of(thick);
  const int64_t plane = grid.dims[0] * grid.dims[1];
  std::vector<int64_t> holding;
  for (int64_t slice = 0; slice < grid.dims[2]; ++slice) {
    if (std::any_of(drawn.begin() + slice * plane, drawn.begin() + (slice + 1) * plane,
                    [](int32_t label) { return label == 1; }))
      holding.push_back(slice);
  }
  ASSERT_EQ(holding.size(), 2u);
  EXPECT_NEAR(grid.to_physical({0, 0, double(holding[0])})[2], -1.5, 1e-9);
  const auto fine = interpolated(thick, cut);
  const auto fine_volumes = label_volumes(fine);
  // Within the 1 % the bias aims at.
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
  // From its middle out, no thin slice holds more of the tube than the one
  // inside it, and none holds it beyond the drawn voxels' reach: the six
  // thin slices between their outer faces hold it (with this bias each
  // holds the drawn slices' whole cross-section, a block the net rounds).
  const auto thin = whole_thin_labels(fine, thick, cut);
  const int64_t slices = grid.dims[2] * cut.parts;
  std::vector<int64_t> area(static_cast<size_t>(slices), 0);
  for (int64_t z = 0; z < slices; ++z)
    area[z] = std::count(thin.begin() + z * plane, thin.begin() + (z + 1) * plane, 1);
  const auto widest = std::max_element(area.begin(), area.end()) - area.begin();
  for (int64_t z = widest + 1; z < slices; ++z) EXPECT_LE(area[z], area[z - 1]) << "slice " << z;
  for (int64_t z = widest - 1; z >= 0; --z) EXPECT_LE(area[z], area[z + 1]) << "slice " << z;
  EXPECT_EQ(std::count_if(area.begin(), area.end(), [](int64_t a) { return a > 0; }), 6);
}

// A sphere of radius 25 mm on 1 x 1 x 3 mm slices, where its walls lean
// more than 45 degrees from the slice axis (the contour moves more than a
// slice's thickness from one slice to the next) and at its poles, beyond
// the last drawn slice: the thin voxels follow the true sphere there.
// Distances clamped at one slice's thickness made terraces of those walls
// half way between slices and a plateau over each pole: 17 % of the thin
// voxels there on the wrong side, against 6 %.
TEST(ThickSlices, ShallowWallsAndPolesFollowTheShape) {
  const auto sphere = testing::sphere_shape(25);
  const auto thick = testing::sample_shape(sphere, {1, 1, 3});
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  ASSERT_EQ(cut.axis, 2);
  const auto fine = interpolated(thick, cut);
  const auto thin = labels_of(fine);
  const auto& d = fine.geometry.dims;
  ASSERT_EQ(thin.size(), static_cast<size_t>(d[0] * d[1] * d[2]));
  size_t shallow = 0, wrong = 0;
  size_t i = 0;
  for (int64_t z = 0; z < d[2]; ++z) {
    for (int64_t y = 0; y < d[1]; ++y) {
      for (int64_t x = 0; x < d[0]; ++x, ++i) {
        const auto p = fine.geometry.to_physical({double(x), double(y), double(z)});
        // Within two pixels of the sphere, where its normal is within 45
        // degrees of the slice axis.
        if (sphere.distance(p) > 2 || std::abs(p[2]) < std::sqrt(0.5) * 25) continue;
        ++shallow;
        wrong += (thin[i] == 1) != sphere.inside(p);
      }
    }
  }
  EXPECT_GT(shallow, 5'000u);
  EXPECT_LT(double(wrong), 0.1 * double(shallow)) << wrong << " of " << shallow;
}

// A cone whose radius grows 2 mm from one 4 mm slice to the next, on
// 0.5 mm pixels: between slices the thin slices' contours grow evenly with
// the cone. Distances measured between pixel centres, with no distance
// within half a pixel of the contour, held each contour on its slice's for
// a while and then moved it faster: a stair of the slices, a fifth of a
// millimetre off the cone midway between a slice and the middle.
TEST(ThickSlices, WallsSlopeEvenlyBetweenSlices) {
  constexpr double kSlope = 0.5, kRadius = 15;  // mm per mm along z; mm at z = 0
  const auto cone = [&](const std::array<double, 3>& p) {
    return std::hypot(p[0], p[1]) < kRadius + kSlope * p[2] ? 1 : 0;
  };
  const auto thick = volume::rasterise(
      volume::centred_grid({101, 101, 9}, {0.5, 0.5, 4}, testing::kIdentityDirection, {0, 0, 0}),
      cone);
  const auto fine = interpolated(thick, {2, 8});
  const auto thin = labels_of(fine);
  const auto& d = fine.geometry.dims;
  const double pixel = 0.5 * 0.5;
  double worst = 0;
  int measured = 0;
  for (int64_t z = 0; z < d[2]; ++z) {
    const double at = fine.geometry.to_physical({0, 0, double(z)})[2];
    if (std::abs(at) > 10) continue;  // the cubic reads two slices either side
    const auto begin = thin.begin() + z * d[0] * d[1];
    const double area = pixel * double(std::count(begin, begin + d[0] * d[1], 1));
    worst = std::max(worst, std::abs(std::sqrt(area / M_PI) - (kRadius + kSlope * at)));
    ++measured;
  }
  EXPECT_GT(measured, 30);
  EXPECT_LT(worst, 0.25) << "mm";
}

// A ball and a thin ring apart on 1 x 1 x 3 mm slices: interpolation thins
// the ring, whose bias brings it back to within 1 % of its voxels' volume,
// while the ball, which it leaves within 1 %, keeps its thin voxels as if the
// ring were not there (the bias bends walls).
TEST(ThickSlices, OnlyLabelsOffTheirVolumeAreBiased) {
  const auto ball_and_ring = [](const std::array<double, 3>& p) {
    const double ball = std::hypot(p[0] + 20, p[1], p[2]);
    const double ring = std::hypot(std::hypot(p[0] - 20, p[1]) - 10, p[2]);
    return ball < 12 ? 1 : ring < 2.5 ? 2 : 0;
  };
  const auto thick = volume::rasterise(
      volume::centred_grid({81, 41, 15}, {1, 1, 3}, testing::kIdentityDirection, {0, 0, 0}),
      ball_and_ring);
  const ThickSlices cut{2, 3};
  const auto both = interpolated(thick, cut);
  auto ball_alone = interpolate_thick_slices(thick, {1}, cut, RunContext{});
  ASSERT_THAT(ball_alone, testing::IsOk());
  const auto with_ring = whole_thin_labels(both, thick, cut);
  const auto without = whole_thin_labels(*ball_alone, thick, cut);
  ASSERT_EQ(with_ring.size(), without.size());
  size_t ball = 0, differ = 0;
  for (size_t i = 0; i < with_ring.size(); ++i) {
    ball += without[i] == 1;
    differ += (with_ring[i] == 1) != (without[i] == 1);
  }
  EXPECT_GT(ball, 5'000u);
  EXPECT_EQ(differ, 0u);
  const auto thick_volumes = label_volumes(thick);
  const auto fine_volumes = label_volumes(both);
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
  EXPECT_NEAR(fine_volumes.at(2) / thick_volumes.at(2), 1.0, 0.01);
}

TEST(ThickSlices, AnyAxisCanBeThick) {
  const auto thick = thick_nested_balls(0);
  const ThickSlices cut = find_thick_slices(thick.geometry, {});
  ASSERT_EQ(cut.axis, 0);
  const auto fine = interpolated(thick, cut);
  const auto thick_volumes = label_volumes(thick);
  const auto fine_volumes = label_volumes(fine);
  EXPECT_NEAR(fine_volumes.at(1) / thick_volumes.at(1), 1.0, 0.01);
  EXPECT_NEAR(fine_volumes.at(2) / thick_volumes.at(2), 1.0, 0.01);
}

TEST(ThickSlices, GiveAConformingMeshOfFiniteElementQuality) {
  const auto thick = thick_nested_balls();
  ConformingFigures figures;
  volume_mesh::ImproveFigures improve;
  auto mesh = mesh_conforming(thick, {}, ConformingParams{}, RunContext{}, figures, improve);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_EQ(figures.thick_slices.axis, 2);
  EXPECT_THAT(check_conforming_mesh(*mesh), testing::IsOk());
  const auto quality = volume_mesh::summarise_quality(*mesh);
  EXPECT_GE(quality.min, 0.2);
  // The slides lift interface tetrahedra and the improvement pass the
  // others to 15 degrees.
  EXPECT_GE(quality.min_dihedral_deg, 15.0);
  EXPECT_EQ(figures.slide.tetrahedra_below_after, 0u);
  ASSERT_EQ(figures.labels.size(), 2u);
  for (const auto& label : figures.labels)
    EXPECT_LT(std::abs(label.volume_change()), 0.02) << "label " << label.label;
}

}  // namespace
}  // namespace labelmesh::conforming
