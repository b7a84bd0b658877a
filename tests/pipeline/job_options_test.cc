// SPDX-License-Identifier: AGPL-3.0-or-later
// Job options: every range is checked in one place (params_from_options), and
// what it accepts survives the trip back to the proto.
#include "core/pipeline/job_options.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "absl/strings/match.h"

namespace labelmesh {
namespace {

TEST(JobOptions, DefaultsAreValidAndSurviveTheRoundTrip) {
  const auto params = params_from_options(v1::MeshOptions());
  ASSERT_TRUE(params.ok()) << params.status();
  const v1::MeshOptions again = make_options(*params);
  const auto reread = params_from_options(again);
  ASSERT_TRUE(reread.ok()) << reread.status();
  EXPECT_EQ(make_options(*reread).SerializeAsString(), again.SerializeAsString());
  EXPECT_DOUBLE_EQ(reread->poisson.min_angle_deg, 30);
  EXPECT_TRUE(reread->guard.fall_back);
}

TEST(JobOptions, SetValuesSurviveTheRoundTrip) {
  v1::MeshOptions options;
  options.add_labels(7);
  options.set_min_angle_deg(25);
  options.set_max_edge_mm(3.5);
  options.set_volume_tolerance_percent(4);
  options.set_hausdorff_tolerance_mm(1.5);
  options.set_strict(true);
  options.set_volume(v1::VOLUME_METHOD_TETGEN);
  options.set_tet_max_volume_mm3(2);
  auto* sizing = options.add_label_sizing();
  sizing->set_label(7);
  sizing->set_max_edge_mm(1.25);
  options.add_formats("ply");
  options.add_formats("vtu");
  const auto params = params_from_options(options);
  ASSERT_TRUE(params.ok()) << params.status();
  EXPECT_EQ(params->labels, std::vector<int32_t>{7});
  EXPECT_DOUBLE_EQ(params->poisson.min_angle_deg, 25);
  EXPECT_DOUBLE_EQ(params->poisson.max_edge_mm, 3.5);
  EXPECT_DOUBLE_EQ(params->guard.volume_percent, 4);
  EXPECT_DOUBLE_EQ(params->guard.hausdorff_mm, 1.5);
  EXPECT_TRUE(params->guard.strict);
  EXPECT_EQ(params->volume, VolumeMethod::kTetgen);
  ASSERT_EQ(params->poisson.label_sizing.size(), 1u);
  EXPECT_DOUBLE_EQ(params->poisson.label_sizing[0].max_edge_mm, 1.25);
  const auto reread = params_from_options(make_options(*params));
  ASSERT_TRUE(reread.ok()) << reread.status();
  EXPECT_DOUBLE_EQ(reread->poisson.label_sizing[0].max_edge_mm, 1.25);
  EXPECT_EQ(reread->formats.size(), 1u);
  EXPECT_EQ(reread->volume_formats.size(), 1u);
}

struct BadOption {
  const char* field;
  std::function<void(v1::MeshOptions&)> set;
};

TEST(JobOptions, EveryOutOfRangeValueIsRefusedByName) {
  const std::vector<BadOption> cases = {
      {"min_angle_deg", [](auto& o) { o.set_min_angle_deg(31); }},
      {"min_angle_deg", [](auto& o) { o.set_min_angle_deg(0); }},
      {"max_edge_voxels", [](auto& o) { o.set_max_edge_voxels(-1); }},
      {"max_distance_voxels", [](auto& o) { o.set_max_distance_voxels(0); }},
      {"max_edge_mm", [](auto& o) { o.set_max_edge_mm(5000); }},
      {"max_distance_mm", [](auto& o) { o.set_max_distance_mm(-2); }},
      {"poisson_min_thickness_voxels", [](auto& o) { o.set_poisson_min_thickness_voxels(-1); }},
      {"smoothing_iterations", [](auto& o) { o.set_smoothing_iterations(500); }},
      {"smoothing_pass_band", [](auto& o) { o.set_smoothing_pass_band(2); }},
      {"point_cluster_size",
       [](auto& o) {
         o.set_point_reduction(v1::POINT_REDUCTION_HIERARCHY);
         o.set_point_cluster_size(0);
       }},
      {"max_points", [](auto& o) { o.set_max_points(10); }},
      {"volume_tolerance_percent", [](auto& o) { o.set_volume_tolerance_percent(150); }},
      {"hausdorff_tolerance_mm", [](auto& o) { o.set_hausdorff_tolerance_mm(-1); }},
      {"label_sizing", [](auto& o) { o.add_label_sizing()->set_label(0); }},
      {"formats", [](auto& o) { o.add_formats("docx"); }},
      {"tet_radius_edge",
       [](auto& o) {
         o.set_volume(v1::VOLUME_METHOD_TETGEN);
         o.set_tet_radius_edge(0.5);
       }},
      {"tet_max_dihedral_deg",
       [](auto& o) {
         o.set_volume(v1::VOLUME_METHOD_TETGEN);
         o.set_tet_max_dihedral_deg(180);
       }},
      {"tet_max_volume_mm3",
       [](auto& o) {
         o.set_volume(v1::VOLUME_METHOD_TETGEN);
         o.set_tet_max_volume_mm3(-1);
       }},
  };
  for (const auto& bad : cases) {
    v1::MeshOptions options;
    bad.set(options);
    const auto params = params_from_options(options);
    ASSERT_FALSE(params.ok()) << bad.field;
    EXPECT_EQ(params.status().code(), absl::StatusCode::kInvalidArgument) << bad.field;
    EXPECT_TRUE(absl::StrContains(params.status().message(), bad.field))
        << bad.field << ": " << params.status().message();
  }
}

}  // namespace
}  // namespace labelmesh
