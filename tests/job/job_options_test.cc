// SPDX-License-Identifier: AGPL-3.0-or-later
// Job options: every range is checked in one place (params_from_options), and
// what it accepts survives the trip back to the proto.
#include "core/job/job_options.h"
#include "support/status_matchers.h"

#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "absl/strings/match.h"

namespace labelmesh {
namespace {

TEST(JobOptions, DefaultsAreValidAndSurviveTheRoundTrip) {
  const auto params = params_from_options(v1::MeshOptions());
  ASSERT_THAT(params, testing::IsOk());
  const v1::MeshOptions again = make_options(*params);
  const auto reread = params_from_options(again);
  ASSERT_THAT(reread, testing::IsOk());
  EXPECT_EQ(make_options(*reread).SerializeAsString(), again.SerializeAsString());
  EXPECT_DOUBLE_EQ(reread->poisson.min_angle_deg, 30);
  EXPECT_TRUE(reread->guard.fall_back);
  EXPECT_TRUE(reread->mesh_on_drawn_grid);
}

TEST(JobOptions, SetValuesSurviveTheRoundTrip) {
  v1::MeshOptions options;
  options.add_labels(7);
  options.set_min_angle_deg(25);
  options.set_max_edge_mm(3.5);
  options.set_volume_tolerance_percent(4);
  options.set_hausdorff_tolerance_mm(1.5);
  options.set_strict(true);
  options.set_mesh_on_drawn_grid(false);
  options.set_volume(v1::VOLUME_METHOD_TETGEN);
  options.set_tet_max_volume_mm3(2);
  auto* sizing = options.add_label_sizing();
  sizing->set_label(7);
  sizing->set_max_edge_mm(1.25);
  options.add_formats("ply");
  options.add_formats("vtu");
  const auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  EXPECT_EQ(params->labels, std::vector<int32_t>{7});
  EXPECT_DOUBLE_EQ(params->poisson.min_angle_deg, 25);
  EXPECT_DOUBLE_EQ(params->poisson.max_edge_mm, 3.5);
  EXPECT_DOUBLE_EQ(params->guard.volume_percent, 4);
  EXPECT_DOUBLE_EQ(params->guard.hausdorff_mm, 1.5);
  EXPECT_TRUE(params->guard.strict);
  EXPECT_FALSE(params->mesh_on_drawn_grid);
  EXPECT_EQ(params->volume, VolumeMethod::kTetgen);
  ASSERT_EQ(params->poisson.label_sizing.size(), 1u);
  EXPECT_DOUBLE_EQ(params->poisson.label_sizing[0].max_edge_mm, 1.25);
  const auto reread = params_from_options(make_options(*params));
  ASSERT_THAT(reread, testing::IsOk());
  EXPECT_DOUBLE_EQ(reread->poisson.label_sizing[0].max_edge_mm, 1.25);
  EXPECT_FALSE(reread->mesh_on_drawn_grid);
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
      // Finer than the voxels can tell apart: only more points.
      {"max_edge_voxels", [](auto& o) { o.set_max_edge_voxels(0.01); }},
      {"max_distance_voxels", [](auto& o) { o.set_max_distance_voxels(0.001); }},
      {"labels",
       [](auto& o) {
         for (int i = 1; i <= 10001; ++i) o.add_labels(i);
       }},
      {"formats",
       [](auto& o) {
         for (int i = 0; i < 250000; ++i) o.add_formats("off");
       }},
      {"label_sizing",
       [](auto& o) {
         for (int i = 0; i < 2; ++i) {
           auto* sizing = o.add_label_sizing();
           sizing->set_label(5);
           sizing->set_max_edge_mm(2);
         }
       }},
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
    EXPECT_THAT(params, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << bad.field;
    EXPECT_TRUE(absl::StrContains(params.status().message(), bad.field))
        << bad.field << ": " << params.status().message();
  }
}

TEST(JobOptions, LabelNamesAreBoundedAndSurviveTheRoundTrip) {
  v1::MeshOptions options;
  auto* liver = options.add_label_names();
  liver->set_label(5);
  liver->set_name("liver");
  for (uint32_t c : {221u, 130u, 101u}) liver->add_colour_rgb(c);
  auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  ASSERT_EQ(params->label_names.size(), 1u);
  EXPECT_EQ(params->label_names[0].colour, (std::array<uint8_t, 3>{221, 130, 101}));
  const v1::MeshOptions again = make_options(*params);
  ASSERT_EQ(again.label_names_size(), 1);
  EXPECT_EQ(again.label_names(0).name(), "liver");

  const std::vector<std::pair<std::function<void(v1::LabelName&)>, std::string>> bad = {
      {[](v1::LabelName& n) { n.set_label(0); }, "must be positive"},
      {[](v1::LabelName& n) { n.set_name(std::string(129, 'a')); }, "over 128 bytes"},
      {[](v1::LabelName& n) { n.set_name("a\nb"); }, "control characters"},
      {[](v1::LabelName& n) { n.add_colour_rgb(1); }, "three values or none"},
      {[](v1::LabelName& n) { n.set_colour_rgb(0, 256); }, "0-255"},
  };
  for (const auto& [spoil, expected] : bad) {
    v1::MeshOptions broken = options;
    spoil(*broken.mutable_label_names(0));
    const auto refused = params_from_options(broken);
    ASSERT_FALSE(refused.ok()) << expected;
    EXPECT_TRUE(absl::StrContains(refused.status().message(), expected)) << refused.status();
  }
  v1::MeshOptions twice = options;
  *twice.add_label_names() = options.label_names(0);
  EXPECT_TRUE(absl::StrContains(params_from_options(twice).status().message(), "more than once"));
  v1::MeshOptions many;
  for (int label = 1; label <= 10001; ++label) many.add_label_names()->set_label(label);
  EXPECT_TRUE(absl::StrContains(params_from_options(many).status().message(), "at most 10000"));
}

TEST(JobOptions, RepeatedLabelsAndFormatsAreKeptOnceInOrder) {
  v1::MeshOptions options;
  for (int label : {7, 3, 7, 7, 3, 9}) options.add_labels(label);
  for (const char* format : {"off", "stl", "off", "off", "stl"}) options.add_formats(format);
  const auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  EXPECT_EQ(params->labels, (std::vector<int32_t>{7, 3, 9}));
  ASSERT_EQ(params->formats.size(), 2u);
  EXPECT_EQ(params->formats[0], surface::SurfaceFormat::kOff);
  EXPECT_EQ(params->formats[1], surface::SurfaceFormat::kStl);
  EXPECT_EQ(make_options(*params).formats_size(), 2);
}

TEST(JobOptions, DicomSurfacesAreAFormatBesideTheSurfaceFiles) {
  v1::MeshOptions options;
  for (const char* format : {"dcm", "stl", "dcm"}) options.add_formats(format);
  auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  EXPECT_TRUE(params->dicom_surfaces);
  EXPECT_EQ(params->formats, std::vector<surface::SurfaceFormat>{surface::SurfaceFormat::kStl});
  const auto again = params_from_options(make_options(*params));
  ASSERT_THAT(again, testing::IsOk());
  EXPECT_TRUE(again->dicom_surfaces);
  EXPECT_EQ(make_options(*again).formats_size(), 2);
  // Another list of formats, without dcm, asks for none.
  options.clear_formats();
  options.add_formats("vtp");
  params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  EXPECT_FALSE(params->dicom_surfaces);
}

TEST(JobOptions, SizingInMillimetresIsCheckedAgainstTheGrid) {
  volume::ImageGeometry geometry;
  geometry.spacing = {3, 3, 3};
  PoissonOptions poisson;
  EXPECT_THAT(check_sizing_for_grid(poisson, geometry), testing::IsOk());
  poisson.max_edge_mm = 1.5;  // half a 3 mm voxel: the finest allowed
  poisson.max_distance_mm = 0.15;
  EXPECT_THAT(check_sizing_for_grid(poisson, geometry), testing::IsOk());
  poisson.max_edge_mm = 1.4;
  auto status = check_sizing_for_grid(poisson, geometry);
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(status.message(), "max_edge_mm")) << status.message();
  poisson.max_edge_mm = 0;
  poisson.label_sizing.push_back({114, 2, 0.01});
  status = check_sizing_for_grid(poisson, geometry);
  EXPECT_TRUE(absl::StrContains(status.message(), "label 114")) << status.message();
  geometry.spacing = {0.1, 0.1, 0.1};  // the same sizing on a fine grid is fine
  EXPECT_THAT(check_sizing_for_grid(poisson, geometry), testing::IsOk());
}

}  // namespace
}  // namespace labelmesh
