// The delivery guard on thin and small shapes: no crash, every label either
// delivered within its tolerance (Poisson or a remeshed fallback with 30
// degree angles) or named in the warnings; --strict turns warnings into a
// failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/pipeline.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/remesh_surface.h"
#include "core/surface/surface_checks.h"
#include "core/surface/surface_statistics.h"
#include "core/surface_fidelity.h"
#include "core/volume/phantom.h"
#include "core/volume/thin_shapes.h"
#include "core/volume/write_label_volume.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

using volume::make_phantom;
using volume::PhantomShape;

std::string phantom_file(PhantomShape shape, const std::string& name) {
  const auto path = (testing::scratch_dir("guard-" + name) / name).string();
  EXPECT_TRUE(volume::write_label_volume(make_phantom(shape).volume, path).ok());
  return path;
}

const SurfaceResult* output_of(const MeshResult& result, int32_t label) {
  for (const auto& s : result.surfaces) {
    if (s.label == label && s.is_output) return &s;
  }
  return nullptr;
}

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
  auto result = run_pipeline(path, MeshParams{}, RunContext{});
  ASSERT_TRUE(result.ok()) << result.status();
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
    EXPECT_EQ(s->stage, chosen.method);
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
  MeshParams params;
  params.guard.strict = true;
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(std::string(result.status().message()).find("strict"), std::string::npos);
}

TEST(DeliveryGuard, OneAndTwoVoxelsKeptAreMeshedOrWarned) {
  const auto path = phantom_file(PhantomShape::kThinShapesAnisotropic, "voxels.nii.gz");
  MeshParams params;
  params.labels = {9, 10};
  params.poisson.min_component_voxels = 1;
  params.poisson.prune_strands = false;
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_TRUE(result.ok()) << result.status();
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
  MeshParams params;
  params.guard.fall_back = false;
  params.guard.hausdorff_mm = 0.05;  // no smooth surface is that near the staircase
  auto result = run_pipeline(path, params, RunContext{});
  ASSERT_TRUE(result.ok()) << result.status();
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
  MeshParams one, four;
  one.threads = 1;
  four.threads = 4;
  auto serial = run_pipeline(path, one, RunContext{});
  auto parallel = run_pipeline(path, four, RunContext{});
  ASSERT_TRUE(serial.ok() && parallel.ok());
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

TEST(RemeshSurface, KeepsAStaircaseSphereWithThirtyDegreeAngles) {
  const auto phantom = make_phantom(PhantomShape::kSphere);
  auto stats = volume::compute_label_statistics(phantom.volume);
  auto surfaces = surface::extract_surfaces(phantom.volume, stats, {1}, RunContext{});
  ASSERT_TRUE(surfaces.ok());
  const auto& staircase = surfaces->front().mesh;
  surface::RemeshParams params;
  params.max_edge_mm = 3;
  params.max_distance_mm = 0.1;
  auto remeshed = surface::remesh_surface(staircase, params, RunContext{});
  ASSERT_TRUE(remeshed.ok()) << remeshed.status();
  const auto s = surface::compute_surface_statistics(*remeshed);
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_GE(s.min_angle_deg, 29.99);
  const double staircase_volume = surface::signed_volume(staircase);
  EXPECT_NEAR(s.volume_mm3 / staircase_volume, 1.0, 0.01);
  const auto distance = surface::surface_distance(*remeshed, staircase, 0.5);
  // Within about a voxel's corner of the staircase everywhere.
  EXPECT_LT(distance.hausdorff_mm, 1.0);
  EXPECT_LT(distance.mean_mm, 0.2);
}

TEST(RemeshSurface, RefusesAnOpenSurfaceAndBadSizes) {
  surface::TriangleMesh open;
  open.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  open.triangles = {{0, 1, 2}};
  surface::RemeshParams params;
  params.max_edge_mm = 1;
  params.max_distance_mm = 0.1;
  EXPECT_EQ(surface::remesh_surface(open, params, RunContext{}).status().code(),
            absl::StatusCode::kInvalidArgument);
  params.max_edge_mm = 0;
  EXPECT_EQ(surface::remesh_surface(open, params, RunContext{}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace labelmesh
