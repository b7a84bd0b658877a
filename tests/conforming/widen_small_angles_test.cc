// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/widen_small_angles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// A flat 4 x 4 grid of points one unit apart (3 x 3 quads between label 1
// and the outside), each in a box of 0.475 around its centre; the border
// points are fixed.
struct FlatNet {
  std::vector<std::array<uint32_t, 4>> quads;
  std::vector<std::array<int32_t, 2>> sides;
  std::vector<Vec3> centre;
  std::vector<Slide> slides;
  std::vector<Vec3> points;
};

FlatNet flat_net() {
  FlatNet net;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      net.centre.push_back({double(x), double(y), 0});
      Slide slide;
      if (x > 0 && x < 3 && y > 0 && y < 3) slide.kind = Slide::Kind::kSurface;
      net.slides.push_back(slide);
    }
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      const uint32_t p = 4 * y + x;
      net.quads.push_back({p, p + 1, p + 5, p + 4});
      net.sides.push_back({0, 1});
    }
  net.points = net.centre;
  return net;
}

double smallest_angle_deg(const FlatNet& net) {
  double worst = -1;
  for (const auto& quad : net.quads)
    worst = std::max(worst, best_quad_split(quad, net.points).cosine);
  return std::acos(worst) * 180 / M_PI;
}

TEST(WidenSmallAngles, TwoPointsPressedTogetherSlideApartAlongTheSurface) {
  FlatNet net = flat_net();
  // Points (1, 1) and (2, 1) pressed into the facing sides of their boxes.
  net.points[5][0] += 0.45;
  net.points[6][0] -= 0.45;
  const double before = smallest_angle_deg(net);
  ASSERT_LT(before, 10);
  PointBoxes boxes;
  boxes.half = {0.475, 0.475, 0.475};
  const auto widened = widen_small_angles(net.quads, net.sides, net.slides, net.centre, boxes,
                                          {0.2, 0.2, 0.2}, {.below_deg = 20}, net.points);
  EXPECT_GE(widened.points_moved, 1u);
  EXPECT_GE(smallest_angle_deg(net), 20);
  for (size_t p = 0; p < net.points.size(); ++p) {
    // Along a flat surface: it stays flat, each point in its box, the
    // fixed ones where they were.
    EXPECT_EQ(net.points[p][2], 0) << p;
    for (int k = 0; k < 2; ++k) EXPECT_LE(std::abs(net.points[p][k] - net.centre[p][k]), 0.475);
    if (net.slides[p].kind == Slide::Kind::kFixed) {
      EXPECT_EQ(net.points[p], net.centre[p]);
    }
  }
}

TEST(WidenSmallAngles, WideAnglesAreLeftAlone) {
  FlatNet net = flat_net();
  net.points[5][0] += 0.2;
  const auto moved_before = net.points;
  PointBoxes boxes;
  boxes.half = {0.475, 0.475, 0.475};
  const auto widened = widen_small_angles(net.quads, net.sides, net.slides, net.centre, boxes,
                                          {0.2, 0.2, 0.2}, {.below_deg = 20}, net.points);
  EXPECT_EQ(widened.points_moved, 0u);
  EXPECT_EQ(net.points, moved_before);
}

// Point (1, 1) lifted h above the flat net, the only point that may move:
// its quads are steep, and sliding along the surface does not widen them
// (its neighbours sit around it alike), so only a move along z does.
FlatNet net_with_a_peak(double h) {
  FlatNet net = flat_net();
  net.points[5][2] = h;
  for (auto& slide : net.slides) slide.kind = Slide::Kind::kFixed;
  net.slides[5].kind = Slide::Kind::kSurface;
  return net;
}

TEST(WidenSmallAngles, AnglesBetweenTheLimitsMoveAcrossOnlyTheShortStep) {
  PointBoxes boxes;
  boxes.half = {0.475, 0.475, 5};
  const AngleLimits limits{.below_deg = 30, .far_below_deg = 20, .short_fraction = 0.25};
  // h = 3: the best split's smallest angle is 25.8 degrees.
  FlatNet between = net_with_a_peak(3);
  const double before = smallest_angle_deg(between);
  ASSERT_GT(before, 20);
  ASSERT_LT(before, 30);
  widen_small_angles(between.quads, between.sides, between.slides, between.centre, boxes,
                     {0.2, 0.2, 0.2}, limits, between.points);
  EXPECT_GT(smallest_angle_deg(between), before);
  // At most one short step (0.05) down in each pass; whole steps (0.2)
  // would take it 0.6 down, to 2.4, where the angle passes 30 degrees.
  const double lowered = 3 - between.points[5][2];
  EXPECT_GT(lowered, 0.04);
  EXPECT_LE(lowered, kWideningPasses * 0.05 + 1e-12);
  EXPECT_LT(lowered, 0.55);
  EXPECT_EQ(between.points[5][0], 1);
  EXPECT_EQ(between.points[5][1], 1);

  // h = 5: 15.9 degrees, below the far limit: the whole step.
  FlatNet far = net_with_a_peak(5);
  ASSERT_LT(smallest_angle_deg(far), 20);
  widen_small_angles(far.quads, far.sides, far.slides, far.centre, boxes, {0.2, 0.2, 0.2}, limits,
                     far.points);
  EXPECT_GE(5 - far.points[5][2], 0.2 - 1e-12);

  // A far limit at the limit itself: the whole step below it.
  FlatNet whole = net_with_a_peak(3);
  widen_small_angles(whole.quads, whole.sides, whole.slides, whole.centre, boxes, {0.2, 0.2, 0.2},
                     {.below_deg = 30, .far_below_deg = 30}, whole.points);
  EXPECT_GE(3 - whole.points[5][2], 0.2 - 1e-12);
}

// A move in a crossing pair is taken back by halves while the pair still
// crosses, then wholly.
TEST(WidenSmallAngles, MovesInCrossingTrianglesAreTakenBackByHalvesThenWhole) {
  InterfaceSurface surface;
  surface.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  surface.triangles = {{0, 1, 2}, {3, 4, 5}};
  surface.widened = {{1, {0.2, 0, 0}}, {4, {6.1, 5, 5}}};
  // A pair that holds no moved point takes nothing back.
  EXPECT_TRUE(take_back_crossing_slides(surface, {}).empty());
  // The move of point 1 is 0.8 long: 0.4, 0.2 and 0.1 of it are left.
  for (const double left : {0.4, 0.2, 0.1}) {
    EXPECT_EQ(take_back_crossing_slides(surface, {{0, 0}}), (std::vector<uint32_t>{0, 1}));
    EXPECT_NEAR(surface.points[1][0], 0.2 + left, 1e-12);
    ASSERT_EQ(surface.widened.size(), 2u);
  }
  EXPECT_EQ(surface.points[4], (Vec3{6, 5, 5}));
  EXPECT_EQ(surface.widened[0].halvings, kHalvings);
  EXPECT_EQ(surface.widened[1].halvings, 0);
  EXPECT_EQ(take_back_crossing_slides(surface, {{0, 0}}), (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(surface.points[1], (Vec3{0.2, 0, 0}));
  ASSERT_EQ(surface.widened.size(), 1u);
  EXPECT_EQ(surface.widened[0].point, 4u);
  EXPECT_TRUE(take_back_crossing_slides(surface, {{0, 0}}).empty());
}

// A kite split along its long diagonal once its top corner is back where
// smoothing left it (after its halvings): the short diagonal gives the
// wider angles.
TEST(WidenSmallAngles, AQuadTakenBackIsSplitAgain) {
  InterfaceSurface surface;
  // A, B, C and D counter-clockwise; D was moved up from (1, 0.2).
  surface.points = {{0, 0, 0}, {1, -0.2, 0}, {2, 0, 0}, {1, 0.6, 0}};
  surface.triangles = {{0, 2, 3}, {2, 0, 1}};
  surface.widened = {{3, {1, 0.2, 0}, kHalvings}};
  EXPECT_EQ(take_back_crossing_slides(surface, {{0, 1}}), (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(surface.points[3], (Vec3{1, 0.2, 0}));
  const std::vector<std::array<uint32_t, 3>> split{{0, 1, 3}, {1, 2, 3}};
  EXPECT_EQ(surface.triangles, split);
}

}  // namespace
}  // namespace labelmesh::conforming
