// SPDX-License-Identifier: AGPL-3.0-or-later
// Distances between surfaces with known answers: the samples must reach the
// apex of a tent, the middle of a long edge and the inside of a triangle.
#include "core/surface/surface_checks.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

namespace labelmesh::surface {
namespace {

// The square [0, side]^2 at height z, two triangles facing +z.
TriangleMesh square(double side, double z) {
  TriangleMesh m;
  m.points = {{0, 0, z}, {side, 0, z}, {side, side, z}, {0, side, z}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(SurfaceDistance, ParallelSquaresAreTheirGapApart) {
  const auto d = surface_distance(square(10, 0), square(10, 0.3), 1.0);
  EXPECT_NEAR(d.hausdorff_mm, 0.3, 1e-12);
  EXPECT_NEAR(d.mean_mm, 0.3, 1e-12);
}

TEST(SurfaceDistance, TheApexOfATentIsWhereItIsFarthest) {
  // The square with its centre raised by 2: four triangles around the apex.
  TriangleMesh tent;
  tent.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {5, 5, 2}};
  tent.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const auto d = surface_distance(tent, square(10, 0), 1.0);
  EXPECT_NEAR(d.hausdorff_mm, 2.0, 1e-12);
  EXPECT_EQ(d.hausdorff_at, (std::array<double, 3>{5, 5, 2}));
  EXPECT_GT(d.mean_mm, 0.5);
  EXPECT_LT(d.mean_mm, 1.0);
}

TEST(SurfaceDistance, AStopRequestEndsTheQueriesEarly) {
  // Fine samples: about 125,000 on each surface, far more than the 4,096
  // queries between two looks at the stop request.
  TriangleMesh tent;
  tent.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {5, 5, 2}};
  tent.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const auto full = surface_distance(square(10, 0), tent, 0.04);
  std::atomic<bool> stop{true};
  RunContext stopping;
  stopping.stop = &stop;
  const auto stopped = surface_distance(square(10, 0), tent, 0.04, stopping);
  // The whole run's mean is about the tent's mean height, 2/3 (a little less
  // from the square's side, measured across the slope). A run stopped from
  // the start measures no chunk of samples at all.
  EXPECT_NEAR(full.mean_mm, 0.64, 0.03);
  EXPECT_LT(stopped.mean_mm, full.mean_mm - 0.1);
}

TEST(SurfaceDistance, AReferenceBuiltAfterAStopIsEmpty) {
  TriangleMesh tent;
  tent.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {5, 5, 2}};
  tent.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  std::atomic<bool> stop{true};
  RunContext stopping;
  stopping.stop = &stop;
  const DistanceReference built(square(10, 0), 0.5);
  const DistanceReference stopped(square(10, 0), 0.5, stopping);
  EXPECT_NEAR(surface_distance(tent, built).hausdorff_mm, 2.0, 1e-12);
  // Neither the tent's samples (no tree) nor the square's (none) are measured.
  const auto nothing = surface_distance(tent, stopped);
  EXPECT_EQ(nothing.hausdorff_mm, 0);
  EXPECT_EQ(nothing.mean_mm, 0);
}

TEST(SurfaceDistance, SharedMeasuringGivesTheSameFigures) {
  TriangleMesh tent;
  tent.points = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}, {5, 5, 2}};
  tent.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  // About 125,000 samples a side: several chunks each.
  const DistanceReference base(square(10, 0), 0.04);
  const auto both = surface_distance(tent, base);

  DistanceMeasurement alone(tent, base);
  alone.work({});
  alone.work({});  // nothing left: returns at once
  const auto one_thread = alone.result();

  // A second thread joining after the first has started.
  DistanceMeasurement shared(tent, base);
  std::atomic<bool> started{false};
  std::thread late([&] {
    while (!started.load()) std::this_thread::yield();
    shared.work({});
  });
  started.store(true);
  shared.work({});
  late.join();
  const auto joined = shared.result();

  for (const auto& d : {one_thread, joined}) {
    EXPECT_EQ(d.hausdorff_mm, both.hausdorff_mm);
    EXPECT_EQ(d.mean_mm, both.mean_mm);
    EXPECT_EQ(d.hausdorff_at, both.hausdorff_at);
  }
  EXPECT_NEAR(both.hausdorff_mm, 2.0, 1e-12);
  EXPECT_NEAR(both.mean_mm, 0.64, 0.03);
}

// Three tiny upright triangles, one standing on each corner of `t`: a surface
// that is near `t` only at its corners.
TriangleMesh posts_at_corners(const TriangleMesh& t) {
  TriangleMesh posts;
  for (const auto& p : t.points) {
    const auto base = static_cast<uint32_t>(posts.points.size());
    posts.points.push_back(p);
    posts.points.push_back({p[0], p[1], p[2] + 0.01});
    posts.points.push_back({p[0] + 0.001, p[1], p[2] + 0.01});
    posts.triangles.push_back({base, base + 1, base + 2});
  }
  return posts;
}

TEST(SurfaceDistance, SamplesReachTheMiddleOfALongEdge) {
  // Right angle at (10, 10): the point farthest from all three corners is
  // the middle of the hypotenuse, 10 from each. Vertex samples alone give 0.
  TriangleMesh right;
  right.points = {{0, 0, 0}, {20, 0, 0}, {10, 10, 0}};
  right.triangles = {{0, 1, 2}};
  const auto d = surface_distance(right, posts_at_corners(right), 0.5);
  EXPECT_NEAR(d.hausdorff_mm, 10.0, 0.002);  // the posts lean 0.001 towards it
  EXPECT_EQ(d.hausdorff_at, (std::array<double, 3>{10, 0, 0}));
}

TEST(SurfaceDistance, SamplesReachTheInsideOfATriangle) {
  // Equilateral, side 10: the centre is 10/sqrt(3) = 5.77 from the corners,
  // every point of an edge at most 5.
  TriangleMesh equilateral;
  equilateral.points = {{0, 0, 0}, {10, 0, 0}, {5, 5 * std::sqrt(3.0), 0}};
  equilateral.triangles = {{0, 1, 2}};
  const auto d = surface_distance(equilateral, posts_at_corners(equilateral), 0.5);
  EXPECT_GT(d.hausdorff_mm, 5.6);
  EXPECT_LE(d.hausdorff_mm, 10 / std::sqrt(3.0) + 1e-9);
}

}  // namespace
}  // namespace labelmesh::surface
