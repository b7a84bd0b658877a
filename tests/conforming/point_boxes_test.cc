// SPDX-License-Identifier: AGPL-3.0-or-later
// The net's point boxes: fixed on an ordinary grid; on a grid cut into
// thinner slices as narrow as ever on and near a drawn slice, and wider
// across the cut axis midway between two.
#include "core/conforming/point_boxes.h"

#include <gtest/gtest.h>

#include "core/conforming/constrained_smoothing.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// A grid of 1 mm pixels whose 3 mm slices (along z) were cut into thirds:
// drawn slices at z = 1 + 3 k, boxes 0.475 mm across and a slice along z,
// half a pixel wider midway between drawn slices.
PointBoxes thirds() {
  PointBoxes boxes;
  boxes.half = {0.475, 0.475, 1.425};
  boxes.drawn_axis = 2;
  boxes.drawn_spacing = 3;
  boxes.drawn_first = 1;
  boxes.widening = {0.5, 0.5, 0};
  boxes.thin_half = 0.475;
  return boxes;
}

TEST(PointBoxes, WithoutDrawnSlicesAPointIsClampedAlongEachAxis) {
  PointBoxes boxes;
  boxes.half = {0.5, 0.25, 1};
  const Vec3 held = boxes.hold(0, {10, 20, 30}, {11, 19, 30.5});
  EXPECT_EQ(held, (Vec3{10.5, 19.75, 30.5}));
}

TEST(PointBoxes, OnAndNearADrawnSliceTheBoxStaysNarrow) {
  const auto boxes = thirds();
  // On the drawn slice z = 4, and a tenth of the way to the middle.
  for (const double z : {4.0, 4.15, 3.85}) {
    const Vec3 held = boxes.hold(0, {5, 5, z}, {7, 3, z});
    EXPECT_DOUBLE_EQ(held[0], 5.475) << z;
    EXPECT_DOUBLE_EQ(held[1], 4.525) << z;
    EXPECT_DOUBLE_EQ(held[2], z) << z;
  }
}

TEST(PointBoxes, MidwayBetweenDrawnSlicesTheBoxIsWiderAcrossOnly) {
  const auto boxes = thirds();
  // z = 5.5 is midway between the drawn slices 4 and 7.
  const Vec3 midway = boxes.hold(0, {5, 5, 5.5}, {7, 3, 5.5});
  EXPECT_DOUBLE_EQ(midway[0], 5.975);
  EXPECT_DOUBLE_EQ(midway[1], 4.025);
  // 0.9 mm from the drawn slice at z = 4 is 0.6 of the way to the middle:
  // (0.6 - 0.2) / 0.8, half the widening.
  const Vec3 partway = boxes.hold(0, {5, 5, 5.5}, {7, 5, 4.9});
  EXPECT_NEAR(partway[0], 5.725, 1e-12);
  // Along the cut axis the box is never wider, and the width across is
  // taken where the point is held along it: z = 9 would be well between
  // drawn slices, but the point is held at 6.925, near the one at 7.
  const Vec3 far_along = boxes.hold(0, {5, 5, 5.5}, {7, 5, 9});
  EXPECT_DOUBLE_EQ(far_along[2], 6.925);
  EXPECT_DOUBLE_EQ(far_along[0], 5.475);
}

// Along the cut axis a point stays between the drawn slices around its
// cube's own box: one carried onto a drawn slice from beside it would bring
// another slice's contour there.
TEST(PointBoxes, APointNeverCrossesADrawnSliceItsCubeDoesNotReach) {
  const auto boxes = thirds();
  // Cube centre z = 4.5, half a thin slice above the drawn slice z = 4: its
  // box along z reaches 3.075, but it stops at 4; upwards it reaches 5.925.
  EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 4.5}, {5, 5, 3.2})[2], 4.0);
  EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 4.5}, {5, 5, 6.5})[2], 5.925);
  // A cube centred on a drawn slice reaches it: its point may leave it
  // either way, as far as its box.
  EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 4}, {5, 5, 2})[2], 2.575);
  EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 4}, {5, 5, 6})[2], 5.425);
  // Stopped on the drawn slice, the point's box across is the drawn
  // slice's, not the one where it was headed.
  const Vec3 stopped = boxes.hold(0, {5, 5, 4.5}, {7, 3, 3.2});
  EXPECT_DOUBLE_EQ(stopped[2], 4.0);
  EXPECT_DOUBLE_EQ(stopped[0], 5.475);
  EXPECT_DOUBLE_EQ(stopped[1], 4.525);
}

// The boxes on a grid of 1 mm pixels whose 3 mm slices were cut into thirds:
// the thin cube's own box along the axis, and the drawn slices, also
// without any widening between them.
TEST(PointBoxes, ThinGridsKnowTheirDrawnSlicesWithOrWithoutWidening) {
  volume::ImageGeometry geometry;
  geometry.dims = {10, 10, 30};
  geometry.spacing = {1, 1, 1};
  InterfaceParams params;
  params.cube_fraction = 0.95;
  params.box_scale = {1, 1, 3};
  params.drawn_axis = 2;
  params.drawn_parts = 3;
  for (const double widening : {0.5, 0.0}) {
    params.between_drawn_widening = widening;
    const auto boxes = point_boxes(geometry, params);
    EXPECT_EQ(boxes.drawn_axis, 2) << widening;
    EXPECT_DOUBLE_EQ(boxes.drawn_spacing, 3) << widening;
    EXPECT_DOUBLE_EQ(boxes.drawn_first, 1) << widening;
    EXPECT_DOUBLE_EQ(boxes.thin_half, 0.475) << widening;
    EXPECT_DOUBLE_EQ(boxes.widening[0], widening) << widening;
    EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 4.5}, {5, 5, 3.2})[2], 4.0) << widening;
  }
}

// The smoothing steps keep the rule too, not only the final hold: point B,
// in the cube above the drawn slice z = 4, is pulled down towards a fixed
// point A at z = 2, and point C, in the cube below, follows B. Held at the
// drawn slice through the steps, B leaves C near it; let past it during the
// steps and held only at the end, B would have drawn C down to z = 3.1.
TEST(PointBoxes, SmoothingStepsKeepPointsOffDrawnSlices) {
  const auto boxes = thirds();
  Stencil stencil;
  stencil.start = {0, 0, 1, 2};  // A: none; B: A; C: B
  stencil.neighbours = {0, 1};
  stencil.along_curve.assign(3, false);
  const std::vector<Vec3> centre{{5, 5, 2.5}, {5, 5, 4.5}, {5, 5, 3.5}};
  std::vector<Vec3> points{{5, 5, 2}, {5, 5, 4.5}, {5, 5, 3.5}};
  InterfaceParams params;
  params.smoothing_rounds = 100;
  params.inflate_step = params.shrink_step;  // plain averaging: no overshoot to read
  smooth_in_boxes(stencil, centre, boxes, params, params.smoothing_rounds, points);
  EXPECT_DOUBLE_EQ(points[0][2], 2.0);
  EXPECT_NEAR(points[1][2], 4.0, 1e-5);
  EXPECT_GT(points[2][2], 3.9);
}

TEST(PointBoxes, NarrowPointsNeverWiden) {
  auto boxes = thirds();
  boxes.narrow = {false, true};
  EXPECT_DOUBLE_EQ(boxes.hold(0, {5, 5, 5.5}, {7, 3, 5.5})[0], 5.975);
  EXPECT_DOUBLE_EQ(boxes.hold(1, {5, 5, 5.5}, {7, 3, 5.5})[0], 5.475);
  // Points past the list widen as any other.
  EXPECT_DOUBLE_EQ(boxes.hold(2, {5, 5, 5.5}, {7, 3, 5.5})[0], 5.975);
}

// The boxes a grid cut into `parts` thin slices gets: on the thin slices
// that lie on drawn slices' centres they stay narrow, halfway between two
// drawn slices they are widest.
TEST(PointBoxes, DrawnSlicesFallOnTheThinSlicesCutFromThem) {
  for (const int parts : {3, 6}) {
    volume::ImageGeometry thin;
    thin.spacing = {0.8, 0.8, 5.0 / parts};
    InterfaceParams params;
    params.cube_fraction = 0.95;
    params.box_scale = {1, 1, double(parts)};
    params.drawn_axis = 2;
    params.drawn_parts = parts;
    params.between_drawn_widening = 0.5;
    const auto boxes = point_boxes(thin, params);
    ASSERT_EQ(boxes.drawn_axis, 2) << parts;
    EXPECT_DOUBLE_EQ(boxes.drawn_spacing, 5) << parts;
    EXPECT_DOUBLE_EQ(boxes.half[0], 0.38) << parts;
    EXPECT_DOUBLE_EQ(boxes.widening[0], 0.4) << parts;
    EXPECT_EQ(boxes.widening[2], 0) << parts;
    // Drawn slice k is thin slice (k + 1/2) parts - 1/2, at that index
    // times the thin spacing.
    const auto place = [&](double thin_index) { return thin_index * thin.spacing[2]; };
    for (const int k : {0, 1, 4}) {
      const double z = place((k + 0.5) * parts - 0.5);
      EXPECT_DOUBLE_EQ(boxes.hold(0, {10, 10, z}, {20, 10, z})[0], 10.38) << parts << " " << k;
      const double midway = z + 2.5;
      EXPECT_NEAR(boxes.hold(0, {10, 10, midway}, {20, 10, midway})[0], 10.78, 1e-9)
          << parts << " " << k;
    }
  }
  // One part is no cut: the boxes stay fixed.
  InterfaceParams uncut;
  uncut.drawn_axis = 2;
  uncut.drawn_parts = 1;
  uncut.between_drawn_widening = 0.5;
  volume::ImageGeometry grid;
  grid.spacing = {1, 1, 3};
  EXPECT_EQ(point_boxes(grid, uncut).drawn_axis, -1);
}

}  // namespace
}  // namespace labelmesh::conforming
