// SPDX-License-Identifier: AGPL-3.0-or-later
// The delivery guard on thin and small shapes: no crash, every label either
// delivered within its tolerance (Poisson or the meshed voxel mask, with 30
// degree angles) or named in the warnings; --strict turns warnings into a
// failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/pipeline/pipeline.h"
#include "core/pipeline/surface_fidelity.h"
#include "core/surface/component_field.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/level_set_surface.h"
#include "core/surface/surface_checks.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/label_components.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/thin_shapes.h"
#include "core/volume/write_label_volume.h"
#include "support/mesh_results.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

// The Poisson path and its guard against Marching Cubes (--surface poisson).
MeshParams poisson_params() {
  MeshParams params;
  params.surface = SurfaceMethod::kPoisson;
  return params;
}

using volume::make_phantom;
using volume::PhantomShape;

std::string phantom_file(PhantomShape shape, const std::string& name) {
  const auto path = (testing::scratch_dir("guard-" + name) / name).string();
  EXPECT_THAT(volume::write_label_volume(make_phantom(shape).volume, path), testing::IsOk());
  return path;
}

using testing::output_of;

const LabelWarning* warning_for(const MeshResult& result, int32_t label) {
  for (const auto& w : result.warnings) {
    if (w.label == label) return &w;
  }
  return nullptr;
}

// Every thin shape either comes out within tolerance, closed, manifold and
// with 30-degree angles (unless only the repaired surface could be built),
// or is named in the warnings; the one- and two-voxel
// labels are too small to mesh.
void expect_every_label_accounted_for(PhantomShape shape, const std::string& name) {
  const auto path = phantom_file(shape, name);
  auto result = run_pipeline(path, poisson_params(), RunContext{});
  ASSERT_THAT(result, testing::IsOk());
  int delivered = 0;
  for (const auto& thin : volume::thin_shapes()) {
    SCOPED_TRACE(std::string(thin.name));
    const SurfaceResult* s = output_of(*result, thin.label);
    const LabelWarning* warning = warning_for(*result, thin.label);
    if (s == nullptr) {
      ASSERT_NE(warning, nullptr) << "label " << thin.label << " vanished without a warning";
      continue;
    }
    ASSERT_TRUE(s->fidelity.has_value());
    EXPECT_EQ(s->fidelity->within_tolerance(), warning == nullptr);
    if (warning != nullptr) continue;
    ++delivered;
    const auto& chosen = s->fidelity->attempts[s->fidelity->delivered];
    EXPECT_LE(std::abs(chosen.volume_change), s->fidelity->tolerance.volume_fraction);
    EXPECT_LE(chosen.hausdorff_mm, s->fidelity->tolerance.hausdorff_mm);
    EXPECT_TRUE(s->statistics.closed);
    EXPECT_TRUE(s->statistics.manifold);
    // The repaired surface is the last resort, with the repair's angles.
    EXPECT_GE(s->statistics.min_angle_deg, s->stage == "repaired" ? 10 : 29.9);
    EXPECT_EQ(s->stage, method_name(chosen.method));
    ASSERT_TRUE(s->self_intersections.has_value());
    EXPECT_EQ(*s->self_intersections, 0u);
  }
  // The one voxel and the two voxels are reported as too small.
  for (int32_t label : {9, 10}) {
    const LabelWarning* warning = warning_for(*result, label);
    ASSERT_NE(warning, nullptr) << "label " << label;
    EXPECT_NE(warning->reason.find("too small to mesh"), std::string::npos) << warning->reason;
    EXPECT_NE(warning->reason.find("64 voxels"), std::string::npos) << warning->reason;
  }
  // Tubes 2-4 voxels across, the torus, helix, arc, plates and the cut tube.
  EXPECT_GE(delivered, 7);
}

TEST(DeliveryGuard, ThinShapesOnA3MillimetreGrid) {
  expect_every_label_accounted_for(PhantomShape::kThinShapes, "thin.nii.gz");
}

TEST(DeliveryGuard, ThinShapesOnAnAnisotropicGrid) {
  expect_every_label_accounted_for(PhantomShape::kThinShapesAnisotropic, "thin-aniso.nii.gz");
}

TEST(DeliveryGuard, StrictFailsWhenALabelIsNotDelivered) {
  const auto path = phantom_file(PhantomShape::kThinShapes, "thin-strict.nii.gz");
  MeshParams params = poisson_params();
  params.guard.strict = true;
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_NE(std::string(result.status().message()).find("strict"), std::string::npos);
}

TEST(DeliveryGuard, OneAndTwoVoxelsKeptAreMeshedOrWarned) {
  const auto path = phantom_file(PhantomShape::kThinShapesAnisotropic, "voxels.nii.gz");
  MeshParams params = poisson_params();
  params.labels = {9, 10};
  params.poisson.min_component_voxels = 1;
  params.poisson.prune_strands = false;
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_THAT(result, testing::IsOk());
  for (int32_t label : {9, 10}) {
    const SurfaceResult* s = output_of(*result, label);
    const bool warned = warning_for(*result, label) != nullptr;
    if (s == nullptr || !s->fidelity->within_tolerance()) {
      EXPECT_TRUE(warned) << "label " << label;
    } else {
      EXPECT_FALSE(warned);
      EXPECT_TRUE(s->statistics.closed);
    }
  }
}

TEST(DeliveryGuard, WithoutFallBackASurfaceOutsideToleranceIsWarnedNotHidden) {
  const auto path = phantom_file(PhantomShape::kSphere, "sphere-tight.nii.gz");
  MeshParams params = poisson_params();
  params.guard.fall_back = false;
  params.guard.hausdorff_mm = 0.05;  // no smooth surface is that near the staircase
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_THAT(result, testing::IsOk());
  const SurfaceResult* s = output_of(*result, 1);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->stage, "poisson");
  ASSERT_EQ(s->fidelity->attempts.size(), 1u);
  EXPECT_FALSE(s->fidelity->within_tolerance());
  const LabelWarning* warning = warning_for(*result, 1);
  ASSERT_NE(warning, nullptr);
  EXPECT_NE(warning->reason.find("outside tolerance"), std::string::npos) << warning->reason;
}

TEST(DeliveryGuard, LabelsInParallelGiveTheSameSurfacesAsOneAtATime) {
  const auto path = phantom_file(PhantomShape::kThinShapes, "thin-threads.nii.gz");
  MeshParams one = poisson_params(), four = poisson_params();
  one.threads = 1;
  four.threads = 4;
  auto serial = run_pipeline(path, one, RunContext{});
  auto parallel = run_pipeline(path, four, RunContext{});
  ASSERT_THAT(serial, testing::IsOk());
  ASSERT_THAT(parallel, testing::IsOk());
  ASSERT_EQ(serial->surfaces.size(), parallel->surfaces.size());
  for (size_t i = 0; i < serial->surfaces.size(); ++i) {
    const auto& a = serial->surfaces[i];
    const auto& b = parallel->surfaces[i];
    EXPECT_EQ(a.label, b.label);
    EXPECT_EQ(a.stage, b.stage);
    EXPECT_EQ(a.mesh.points, b.mesh.points) << "label " << a.label;
    EXPECT_EQ(a.mesh.triangles, b.mesh.triangles) << "label " << a.label;
  }
  ASSERT_EQ(serial->warnings.size(), parallel->warnings.size());
  for (size_t i = 0; i < serial->warnings.size(); ++i)
    EXPECT_EQ(serial->warnings[i].reason, parallel->warnings[i].reason);
}

// The torus (a tube of radius 6 voxels, 3V/A = 1.5 r = 9 voxels) is thinner
// than the 15 voxels from which Poisson is tried first: by default its first
// surface is the meshed mask; asked to, or without fall-back, it is Poisson.
TEST(DeliveryGuard, ThinLabelsStartWithTheMaskUnlessPoissonIsAskedFor) {
  const auto path = phantom_file(PhantomShape::kTorus, "torus.mha");
  auto first_attempt = [&](const MeshParams& params) {
    auto result = run_pipeline(path, params, RunContext{});
    EXPECT_THAT(result, testing::IsOk());
    const SurfaceResult* s = result.ok() ? output_of(*result, 1) : nullptr;
    EXPECT_TRUE(s != nullptr && s->fidelity && !s->fidelity->attempts.empty());
    return s != nullptr && s->fidelity && !s->fidelity->attempts.empty() ? *s : SurfaceResult{};
  };
  const SurfaceResult by_default = first_attempt(poisson_params());
  ASSERT_TRUE(by_default.fidelity);
  EXPECT_NEAR(by_default.fidelity->thickness_voxels, 9, 1);
  EXPECT_EQ(by_default.fidelity->attempts.front().method, SurfaceAttemptMethod::kMask);
  EXPECT_FALSE(by_default.poisson.has_value());
  EXPECT_TRUE(by_default.fidelity->within_tolerance());
  EXPECT_GE(by_default.statistics.min_angle_deg, 29.99);

  MeshParams everywhere = poisson_params();
  everywhere.poisson.min_thickness_voxels = 0;
  const SurfaceResult asked = first_attempt(everywhere);
  ASSERT_TRUE(asked.fidelity);
  EXPECT_EQ(asked.fidelity->attempts.front().method, SurfaceAttemptMethod::kPoisson);
  EXPECT_TRUE(asked.poisson.has_value());

  MeshParams no_fall_back = poisson_params();
  no_fall_back.guard.fall_back = false;
  const SurfaceResult measured = first_attempt(no_fall_back);
  ASSERT_TRUE(measured.fidelity);
  EXPECT_EQ(measured.fidelity->attempts.front().method, SurfaceAttemptMethod::kPoisson);
}

TEST(DeliveryGuard, TolerancesFollowLabelSizeAndDrawnSpacing) {
  const auto small = tolerance_for(999, {0.6, 0.6, 2.0}, 3, 10, 0);
  EXPECT_DOUBLE_EQ(small.volume_fraction, 0.10);
  EXPECT_DOUBLE_EQ(small.hausdorff_mm, 2.0);
  const auto large = tolerance_for(1000, {0.6, 0.6, 2.0}, 3, 10, 1.5);
  EXPECT_DOUBLE_EQ(large.volume_fraction, 0.03);
  EXPECT_DOUBLE_EQ(large.hausdorff_mm, 1.5);
  SurfaceAttempt attempt;
  attempt.volume_change = -0.02;
  attempt.hausdorff_mm = 1.9;
  EXPECT_TRUE(is_within(attempt, small));
  EXPECT_FALSE(is_within(attempt, large));
  EXPECT_NEAR(excess_over(attempt, large), 1.9 / 1.5, 1e-12);
  attempt.error = "failed";
  EXPECT_FALSE(is_within(attempt, small));
  EXPECT_TRUE(std::isinf(excess_over(attempt, small)));
}

TEST(LevelSetSurface, MeshesASphereMaskWithThirtyDegreeAnglesCloseToItsVoxels) {
  const auto phantom = make_phantom(PhantomShape::kSphere);
  const auto statistics = volume::compute_label_statistics(phantom.volume);
  auto components = volume::find_label_components(phantom.volume, *statistics.find(1),
                                                  volume::ComponentOptions{}, RunContext{});
  ASSERT_THAT(components, testing::IsOk());
  ASSERT_EQ(components->components.size(), 1u);
  auto marching_cubes =
      surface::extract_component_surfaces(*components, {1}, phantom.volume.geometry, RunContext{});
  ASSERT_THAT(marching_cubes, testing::IsOk());
  const auto& staircase = marching_cubes->front();
  auto field = surface::component_field(*components, 1, phantom.volume.geometry, 0.4);
  ASSERT_THAT(field, testing::IsOk());
  surface::LevelSetParams params;
  params.max_edge_mm = 3;
  params.max_distance_mm = 0.1;
  auto mesh = surface::mesh_level_set(*field, params, staircase.points, RunContext{});
  ASSERT_THAT(mesh, testing::IsOk());
  const auto s = surface::compute_surface_statistics(*mesh);
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_GE(s.min_angle_deg, 29.99);
  EXPECT_NEAR(s.volume_mm3 / surface::signed_volume(staircase), 1.0, 0.01);
  const auto distance = surface::surface_distance(*mesh, staircase, 0.5);
  // Within a voxel's corner of the staircase everywhere, and far closer on
  // average.
  EXPECT_LT(distance.hausdorff_mm, 1.0);
  EXPECT_LT(distance.mean_mm, 0.2);
}

// A ball's signed distance sampled on an anisotropic, rotated and mirrored
// grid: the meshed level set lies on the ball wherever the grid puts it.
TEST(LevelSetSurface, PlacesTheSurfaceThroughTheGridsPlacement) {
  surface::ScalarGrid grid;
  grid.dims = {40, 30, 16};
  grid.origin = {-20, 35, 7};
  // Axis 0 along -y (0.8 mm), axis 1 along x (1.1 mm), axis 2 along z (2.5 mm).
  grid.index_to_mm = {0, 1.1, 0, -0.8, 0, 0, 0, 0, 2.5};
  const std::array<double, 3> centre{-4, 20, 26};
  const double radius = 9;
  grid.values.resize(size_t(40 * 30 * 16));
  size_t at = 0;
  for (int k = 0; k < 16; ++k) {
    for (int j = 0; j < 30; ++j) {
      for (int i = 0; i < 40; ++i, ++at) {
        const std::array<double, 3> p{grid.origin[0] + 1.1 * j, grid.origin[1] - 0.8 * i,
                                      grid.origin[2] + 2.5 * k};
        grid.values[at] =
            float(radius - std::hypot(p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]));
      }
    }
  }
  surface::LevelSetParams params;
  params.level = 0;
  params.max_edge_mm = 2;
  params.max_distance_mm = 0.05;
  const std::vector<std::array<double, 3>> seeds{{centre[0] + radius, centre[1], centre[2]}};
  auto mesh = surface::mesh_level_set(grid, params, seeds, RunContext{});
  ASSERT_THAT(mesh, testing::IsOk());
  double worst = 0;
  for (const auto& p : mesh->points) {
    const double r = std::hypot(p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]);
    worst = std::max(worst, std::abs(r - radius));
  }
  // Trilinear interpolation cuts the ball's curve by at most h^2 / 8R
  // (0.09 mm along the 2.5 mm axis), plus the mesher's 0.05 mm bound; a
  // misplaced axis would put points millimetres off.
  EXPECT_LT(worst, 0.15);
  const auto s = surface::compute_surface_statistics(*mesh);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_GE(s.min_angle_deg, 29.99);
  // Less the chords of 2 mm triangles and the interpolation's cut.
  EXPECT_NEAR(s.volume_mm3 / (4.0 / 3 * M_PI * radius * radius * radius), 0.98, 0.01);
}

TEST(LevelSetSurface, RefusesBadGridsAndSizes) {
  surface::ScalarGrid grid;
  grid.dims = {3, 3, 3};
  grid.values.assign(27, 0.0f);
  grid.values[13] = 1;
  surface::LevelSetParams params;
  params.max_edge_mm = 1;
  params.max_distance_mm = 0.1;
  const std::vector<std::array<double, 3>> seeds{{0.5, 1, 1}};
  EXPECT_THAT(surface::mesh_level_set(grid, params, seeds, RunContext{}), testing::IsOk());
  auto expect_refused = [&](const surface::ScalarGrid& g, const surface::LevelSetParams& p,
                            const std::vector<std::array<double, 3>>& s) {
    EXPECT_EQ(surface::mesh_level_set(g, p, s, RunContext{}).status().code(),
              absl::StatusCode::kInvalidArgument);
  };
  auto short_grid = grid;
  short_grid.values.pop_back();
  expect_refused(short_grid, params, seeds);
  // Sides whose product wraps around 2^64 to the number of values.
  auto wrapping = grid;
  wrapping.dims = {int64_t(1) << 32, int64_t(1) << 32, 4};
  wrapping.values.clear();
  expect_refused(wrapping, params, seeds);
  auto flat = grid;
  flat.index_to_mm = {1, 0, 0, 0, 1, 0, 0, 0, 0};
  expect_refused(flat, params, seeds);
  auto bad_edge = params;
  bad_edge.max_edge_mm = 0;
  expect_refused(grid, bad_edge, seeds);
  auto bad_angle = params;
  bad_angle.min_angle_deg = 31;
  expect_refused(grid, bad_angle, seeds);
  // Nothing above the level, and no seeds at all.
  auto empty = grid;
  empty.values.assign(27, 0.0f);
  expect_refused(empty, params, seeds);
  expect_refused(grid, params, {});
  // An unknown component, and a negative smoothing.
  volume::LabelComponents none;
  EXPECT_EQ(surface::component_field(none, 1, volume::ImageGeometry{}, 0.4).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace labelmesh
