// SPDX-License-Identifier: AGPL-3.0-or-later
// The CLI's pipeline flags reach the pipeline as given: through the job
// options message written by make_options and read by params_from_options,
// the path both `labelmesh mesh` and `labelmesh submit` take.
#include "client/pipeline_options.h"

#include <gtest/gtest.h>
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/job/job_options.h"
#include "support/status_matchers.h"

namespace labelmesh::client {
namespace {

// The job options `labelmesh mesh ARGS` runs with, or the CLI's error.
absl::StatusOr<v1::MeshOptions> options_of(std::vector<std::string> arguments) {
  CLI::App app;
  PipelineFlags flags;
  add_pipeline_flags(app, flags);
  std::reverse(arguments.begin(), arguments.end());  // CLI11 parses a reversed vector
  app.parse(arguments);
  return to_mesh_options(flags);
}

MeshParams params_of(std::vector<std::string> arguments) {
  auto options = options_of(std::move(arguments));
  EXPECT_TRUE(options.ok()) << options.status();
  auto params = params_from_options(*options);
  EXPECT_TRUE(params.ok()) << params.status();
  return params.ok() ? *params : MeshParams{};
}

TEST(PipelineFlags, NoFlagsGiveThePipelinesDefaults) {
  const auto options = options_of({});
  ASSERT_THAT(options, testing::IsOk());
  // The surface is left to the job options: net, or poisson under a volume.
  EXPECT_EQ(options->surface(), v1::SURFACE_METHOD_UNSPECIFIED);
  const MeshParams params = params_of({});
  const MeshParams defaults;
  EXPECT_EQ(params.surface, SurfaceMethod::kNet);
  EXPECT_EQ(params.volume, VolumeMethod::kNone);
  EXPECT_EQ(params.poisson.min_angle_deg, defaults.poisson.min_angle_deg);
  EXPECT_EQ(params.poisson.max_edge_voxels, defaults.poisson.max_edge_voxels);
  EXPECT_EQ(params.poisson.prune_strands, defaults.poisson.prune_strands);
  EXPECT_EQ(params.poisson.adapt_to_thickness, defaults.poisson.adapt_to_thickness);
  EXPECT_EQ(params.guard.fall_back, defaults.guard.fall_back);
  EXPECT_TRUE(params.mesh_on_drawn_grid);
  EXPECT_EQ(params.guard.volume_percent, defaults.guard.volume_percent);
  EXPECT_EQ(params.limits.max_voxels, defaults.limits.max_voxels);
  EXPECT_EQ(params.formats, defaults.formats);
  EXPECT_EQ(params.frame, CoordinateFrame::kLps);
  EXPECT_FALSE(params.limits.separate_overlapping);
  EXPECT_EQ(params_of({"--volume", "tet"}).surface, SurfaceMethod::kPoisson);
  EXPECT_EQ(params_of({"--volume", "conforming"}).surface, SurfaceMethod::kNet);
}

TEST(PipelineFlags, EveryFlagReachesThePipeline) {
  const MeshParams p = params_of({"--labels",
                                  "3,1",
                                  "--surface",
                                  "repaired",
                                  "--min-angle",
                                  "25",
                                  "--max-edge",
                                  "6",
                                  "--max-distance",
                                  "0.4",
                                  "--min-component-voxels",
                                  "12",
                                  "--max-edge-mm",
                                  "4",
                                  "--max-distance-mm",
                                  "0.3",
                                  "--no-adapt-to-thickness",
                                  "--poisson-min-thickness",
                                  "2.5",
                                  "--label-sizing",
                                  "5:2:0.2",
                                  "--label-sizing",
                                  "7:3",
                                  "--volume-tolerance",
                                  "4",
                                  "--small-volume-tolerance",
                                  "12",
                                  "--hausdorff-tolerance",
                                  "1.5",
                                  "--no-fall-back",
                                  "--file-grid",
                                  "--strict",
                                  "--keep-strands",
                                  "--smoothing-iterations",
                                  "7",
                                  "--smoothing-pass-band",
                                  "0.2",
                                  "--normals",
                                  "area",
                                  "--point-reduction",
                                  "hierarchy",
                                  "--point-cell",
                                  "1.5",
                                  "--max-points",
                                  "5000",
                                  "--split-points",
                                  "9000",
                                  "--point-cluster-size",
                                  "20",
                                  "--volume",
                                  "mixed",
                                  "--hex-size",
                                  "2",
                                  "--hex-interior-size",
                                  "8",
                                  "--conforming-max-faces",
                                  "77",
                                  "--tet-radius-edge",
                                  "1.8",
                                  "--tet-min-dihedral",
                                  "12",
                                  "--tet-max-volume",
                                  "9",
                                  "--tet-max-dihedral",
                                  "160",
                                  "--tet-improve-quality",
                                  "0.2",
                                  "--tet-split-boundary",
                                  "--formats",
                                  "stl,ply,vtu,vtm",
                                  "--coordinates",
                                  "ras",
                                  "--overlapping",
                                  "separate",
                                  "--max-voxels",
                                  "1000000"});
  EXPECT_EQ(p.labels, (std::vector<int32_t>{3, 1}));
  EXPECT_EQ(p.surface, SurfaceMethod::kRepaired);
  EXPECT_EQ(p.poisson.min_angle_deg, 25);
  EXPECT_EQ(p.poisson.max_edge_voxels, 6);
  EXPECT_EQ(p.poisson.max_distance_voxels, 0.4);
  EXPECT_EQ(p.poisson.min_component_voxels, 12u);
  EXPECT_EQ(p.poisson.max_edge_mm, 4);
  EXPECT_EQ(p.poisson.max_distance_mm, 0.3);
  EXPECT_FALSE(p.poisson.adapt_to_thickness);
  EXPECT_EQ(p.poisson.min_thickness_voxels, 2.5);
  ASSERT_EQ(p.poisson.label_sizing.size(), 2u);
  EXPECT_EQ(p.poisson.label_sizing[0].label, 5);
  EXPECT_EQ(p.poisson.label_sizing[0].max_edge_mm, 2);
  EXPECT_EQ(p.poisson.label_sizing[0].max_distance_mm, 0.2);
  EXPECT_EQ(p.poisson.label_sizing[1].label, 7);
  EXPECT_EQ(p.poisson.label_sizing[1].max_distance_mm, 0);
  EXPECT_EQ(p.guard.volume_percent, 4);
  EXPECT_EQ(p.guard.small_volume_percent, 12);
  EXPECT_EQ(p.guard.hausdorff_mm, 1.5);
  EXPECT_FALSE(p.guard.fall_back);
  EXPECT_FALSE(p.mesh_on_drawn_grid);
  EXPECT_TRUE(p.guard.strict);
  EXPECT_FALSE(p.poisson.prune_strands);
  EXPECT_EQ(p.poisson.smoothing.iterations, 7);
  EXPECT_EQ(p.poisson.smoothing.pass_band, 0.2);
  EXPECT_EQ(p.poisson.normals, surface::NormalWeighting::kArea);
  EXPECT_EQ(p.poisson.point_reduction, surface::PointReduction::kHierarchy);
  EXPECT_EQ(p.poisson.point_cell_voxels, 1.5);
  EXPECT_EQ(p.poisson.max_points, 5000u);
  EXPECT_EQ(p.poisson.split_points, 9000u);
  EXPECT_EQ(p.poisson.point_cluster_size, 20);
  EXPECT_EQ(p.volume, VolumeMethod::kMixed);
  EXPECT_EQ(p.hex_size_mm, 2);
  EXPECT_EQ(p.hex_interior_size_mm, 8);
  EXPECT_EQ(p.conforming_max_interface_faces, 77u);
  EXPECT_EQ(p.tetgen.radius_edge_ratio, 1.8);
  EXPECT_EQ(p.tetgen.min_dihedral_deg, 12);
  EXPECT_EQ(p.tetgen.max_volume_mm3, 9);
  EXPECT_EQ(p.tetgen.max_dihedral_deg, 160);
  EXPECT_EQ(p.improve.target_quality, 0.2);
  EXPECT_FALSE(p.tetgen.keep_boundary);
  EXPECT_EQ(p.formats, (std::vector<surface::SurfaceFormat>{surface::SurfaceFormat::kStl,
                                                            surface::SurfaceFormat::kPly}));
  EXPECT_EQ(p.volume_formats,
            (std::vector<volume_mesh::VolumeFormat>{volume_mesh::VolumeFormat::kVtu}));
  EXPECT_EQ(p.scene_formats, (std::vector<SceneFormat>{SceneFormat::kVtm}));
  EXPECT_EQ(p.frame, CoordinateFrame::kRas);
  EXPECT_TRUE(p.limits.separate_overlapping);
  EXPECT_EQ(p.limits.max_voxels, 1000000u);
}

TEST(PipelineFlags, LabelTablesAndBadSizingsComeThrough) {
  const auto dir = std::filesystem::temp_directory_path() / "labelmesh-pipeline-flags";
  std::filesystem::create_directories(dir);
  const auto table = (dir / "names.json").string();
  std::ofstream(table) << R"({"5": "liver", "7": "spleen"})";
  const MeshParams p = params_of({"--label-names", table});
  ASSERT_EQ(p.label_names.size(), 2u);
  EXPECT_EQ(p.label_names[0].label, 5);
  EXPECT_EQ(p.label_names[0].name, "liver");
  EXPECT_EQ(p.label_names[1].name, "spleen");
  std::filesystem::remove_all(dir);

  const auto bad = options_of({"--label-sizing", "5-2"});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("5-2"), std::string::npos);
  EXPECT_EQ(options_of({"--label-names", "/no/such/table.json"}).status().code(),
            absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace labelmesh::client
