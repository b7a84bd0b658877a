// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/smooth_surface.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/surface/extract_surfaces.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "support/status_matchers.h"

namespace labelmesh::surface {
namespace {

using volume::make_phantom;
using volume::PhantomShape;

TriangleMesh marching_cubes(const volume::Phantom& phantom) {
  const auto stats = volume::compute_label_statistics(phantom.volume);
  auto surfaces = extract_surfaces(phantom.volume, stats, {1}, RunContext{});
  EXPECT_THAT(surfaces, testing::IsOk());
  return surfaces.ok() && !surfaces->empty() ? std::move((*surfaces)[0].mesh) : TriangleMesh{};
}

double rms_radial_error(const TriangleMesh& mesh, const std::array<double, 3>& c, double radius) {
  double sum = 0;
  for (const auto& p : mesh.points) {
    const double e = std::hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]) - radius;
    sum += e * e;
  }
  return std::sqrt(sum / double(mesh.points.size()));
}

TEST(SmoothSurface, FlattensTheStaircaseWithoutShrinking) {
  const auto phantom = make_phantom(PhantomShape::kSphere);
  const TriangleMesh staircase = marching_cubes(phantom);
  ASSERT_GT(staircase.points.size(), 1000u);
  auto smoothed = smooth_surface(staircase, SmoothingParams{}, RunContext{});
  ASSERT_THAT(smoothed, testing::IsOk());
  // Connectivity is untouched: same points, same triangles.
  ASSERT_EQ(smoothed->points.size(), staircase.points.size());
  EXPECT_EQ(smoothed->triangles, staircase.triangles);
  const double before = rms_radial_error(staircase, phantom.centre, 20);
  const double after = rms_radial_error(*smoothed, phantom.centre, 20);
  // Measured 0.208 voxel before and 0.05 after.
  EXPECT_GT(before, 0.18);
  EXPECT_LT(after, 0.1);
  // Windowed sinc, unlike Laplacian smoothing, keeps the volume.
  const double v0 = compute_surface_statistics(staircase).volume_mm3;
  const double v1 = compute_surface_statistics(*smoothed).volume_mm3;
  EXPECT_NEAR(v1 / v0, 1.0, 0.01);
  EXPECT_NEAR(v1 / phantom.truth[0].volume_mm3, 1.0, 0.02);
}

TEST(SmoothSurface, ZeroIterationsLeavesTheSurfaceAlone) {
  const TriangleMesh staircase = marching_cubes(make_phantom(PhantomShape::kTorus));
  SmoothingParams off;
  off.iterations = 0;
  auto same = smooth_surface(staircase, off, RunContext{});
  ASSERT_THAT(same, testing::IsOk());
  EXPECT_EQ(same->points, staircase.points);
  EXPECT_EQ(same->triangles, staircase.triangles);
}

TEST(SmoothSurface, BadParametersAreRefused) {
  const TriangleMesh staircase = marching_cubes(make_phantom(PhantomShape::kSphere));
  SmoothingParams negative;
  negative.iterations = -1;
  SmoothingParams wide;
  wide.pass_band = 2;
  for (const auto& params : {negative, wide}) {
    auto refused = smooth_surface(staircase, params, RunContext{});
    EXPECT_THAT(refused, testing::StatusIs(absl::StatusCode::kInvalidArgument));
    EXPECT_NE(std::string(refused.status().message()).find("smoothing-"), std::string::npos);
  }
}

TEST(SmoothSurface, StopsWhenAskedTo) {
  const TriangleMesh staircase = marching_cubes(make_phantom(PhantomShape::kSphere));
  std::atomic<bool> stop{true};
  RunContext context;
  context.stop = &stop;
  EXPECT_EQ(smooth_surface(staircase, SmoothingParams{}, context).status().code(),
            absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace labelmesh::surface
