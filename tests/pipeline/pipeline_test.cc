// SPDX-License-Identifier: AGPL-3.0-or-later
// run_pipeline and write_results end to end on phantoms: the stages a run
// lists, one output surface per label, the files written, and the errors a
// caller gets for a bad request.
#include "core/pipeline/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <tuple>

#include "absl/strings/match.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/read_label_volume.h"
#include "core/volume/write_label_volume.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

namespace fs = std::filesystem;

std::string write_phantom(const fs::path& dir, volume::PhantomShape shape) {
  const auto path = (dir / "phantom.nii.gz").string();
  const auto status = volume::write_label_volume(volume::make_phantom(shape).volume, path);
  EXPECT_THAT(status, testing::IsOk());
  return path;
}

MeshParams repaired_params() {
  MeshParams params;
  params.surface = SurfaceMethod::kRepaired;
  return params;
}

TEST(Pipeline, OneOutputSurfacePerLabelAndItsFilesWritten) {
  const fs::path dir = testing::scratch_dir("pipeline_outputs");
  const std::string input = write_phantom(dir, volume::PhantomShape::kNestedSpheres);
  auto result = run_pipeline(input, repaired_params(), {});
  ASSERT_THAT(result, testing::IsOk());
  std::set<int32_t> output_labels;
  for (const auto& surface : result->surfaces) {
    if (!surface.is_output) continue;
    EXPECT_TRUE(output_labels.insert(surface.label).second) << "label " << surface.label;
    EXPECT_TRUE(surface.statistics.closed) << "label " << surface.label;
  }
  EXPECT_EQ(output_labels, (std::set<int32_t>{1, 2, 3}));
  EXPECT_TRUE(result->warnings.empty());
  std::set<std::string> stages;
  for (const auto& stage : result->stages) stages.insert(stage.name);
  for (const char* stage : {"read", "label_statistics", "marching_cubes", "repair"})
    EXPECT_TRUE(stages.count(stage)) << stage;

  MeshParams params = repaired_params();
  params.formats = {surface::SurfaceFormat::kPly, surface::SurfaceFormat::kStl};
  const fs::path out = dir / "out";
  ASSERT_THAT(write_results(*result, params, out.string(), {}), testing::IsOk());
  size_t files = 0;
  for (const auto& surface : result->surfaces) {
    EXPECT_EQ(surface.files.size(), surface.is_output ? 2u : 0u) << surface.stage;
    for (const auto& name : surface.files) {
      EXPECT_GT(fs::file_size(out / name), 0u) << name;
      ++files;
    }
  }
  EXPECT_EQ(files, 6u);
  EXPECT_GT(fs::file_size(out / "report.json"), 0u);
}

// Stages that work label by label say which label, its name and its place;
// whole-volume stages name none.
TEST(Pipeline, ProgressNamesTheLabelAndItsPlace) {
  const fs::path dir = testing::scratch_dir("pipeline_progress");
  const std::string input = write_phantom(dir, volume::PhantomShape::kNestedSpheres);
  MeshParams params = repaired_params();
  params.label_names = {volume::named_label(2, "kidney")};
  std::mutex mutex;
  std::set<std::string> whole_volume_stages;
  std::map<int32_t, std::set<std::string>> label_stages;
  std::map<int32_t, std::tuple<std::string, uint32_t, uint32_t>> places;
  RunContext context;
  context.progress = [&](const ProgressUpdate& update) {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_GE(update.fraction, 0.0);
    EXPECT_LE(update.fraction, 1.0);
    if (update.label == nullptr) {
      whole_volume_stages.insert(std::string(update.stage));
      return;
    }
    const LabelInProgress& label = *update.label;
    label_stages[label.label].insert(std::string(update.stage));
    places[label.label] = {label.name, label.index, label.count};
    EXPECT_LT(label.done, label.count);
  };
  ASSERT_THAT(run_pipeline(input, params, context), testing::IsOk());
  EXPECT_TRUE(whole_volume_stages.count("read"));
  EXPECT_TRUE(whole_volume_stages.count("marching_cubes"));
  EXPECT_FALSE(whole_volume_stages.count("repair"));
  ASSERT_EQ(places.size(), 3u);
  EXPECT_EQ(places[1], std::make_tuple(std::string(), 1u, 3u));
  EXPECT_EQ(places[2], std::make_tuple(std::string("kidney"), 2u, 3u));
  EXPECT_EQ(places[3], std::make_tuple(std::string(), 3u, 3u));
  for (int32_t label : {1, 2, 3}) EXPECT_TRUE(label_stages[label].count("repair")) << label;
}

// The scene files: every surface in one multiblock file and the label volume
// beside them, in the frame asked for; report.json lists them and the frame.
TEST(Pipeline, SceneFilesAndTheRasFrame) {
  const fs::path dir = testing::scratch_dir("pipeline_scene");
  const std::string input = write_phantom(dir, volume::PhantomShape::kNestedSpheres);
  MeshParams params = repaired_params();
  params.formats = {surface::SurfaceFormat::kVtp};
  params.scene_formats = {SceneFormat::kVtm, SceneFormat::kVti, SceneFormat::kMha};
  params.frame = CoordinateFrame::kRas;
  auto result = run_pipeline(input, params, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_NE(result->label_image, nullptr);
  const fs::path out = dir / "out";
  ASSERT_THAT(write_results(*result, params, out.string(), {}), testing::IsOk());
  EXPECT_EQ(result->scene_files,
            (std::vector<std::string>{"surfaces.vtm", "surfaces/surfaces_0.vtp",
                                      "surfaces/surfaces_1.vtp", "surfaces/surfaces_2.vtp",
                                      "labels.vti", "labels.mha"}));
  for (const auto& name : result->scene_files) EXPECT_TRUE(fs::exists(out / name)) << name;
  const v1::Report report = make_report(*result, params);
  EXPECT_EQ(report.files_frame(), "RAS");
  EXPECT_EQ(report.scene_files_size(), 6);
  EXPECT_EQ(report.options().coordinates(), v1::COORDINATE_FRAME_RAS);

  // The MetaImage is the input as read, in LPS as ITK reads it; the VTI is
  // the same voxels placed in RAS.
  const auto& g = result->input.geometry;
  auto mha = volume::read_label_volume((out / "labels.mha").string(), {}, {});
  ASSERT_THAT(mha, testing::IsOk());
  auto vti = volume::read_label_volume((out / "labels.vti").string(), {}, {});
  ASSERT_THAT(vti, testing::IsOk());
  const auto mha_stats = volume::compute_label_statistics(*mha);
  EXPECT_EQ(mha_stats.labels.size(), 3u);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(mha->geometry.dims[axis], g.dims[axis]);
    EXPECT_NEAR(mha->geometry.origin[axis], g.origin[axis], 1e-9);
    const double sign = axis < 2 ? -1 : 1;
    EXPECT_NEAR(vti->geometry.origin[axis], sign * g.origin[axis], 1e-9);
    EXPECT_NEAR(vti->geometry.direction[3 * axis + axis], sign * g.direction[3 * axis + axis],
                1e-12);
  }
}

TEST(Pipeline, BadRequestsGetTheirOwnCodesNamingTheCause) {
  const fs::path dir = testing::scratch_dir("pipeline_errors");
  const std::string missing = (dir / "no-such.nii.gz").string();
  auto result = run_pipeline(missing, repaired_params(), {});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kNotFound));
  EXPECT_TRUE(absl::StrContains(result.status().message(), "no-such.nii.gz"));

  const std::string sphere = write_phantom(dir, volume::PhantomShape::kSphere);
  MeshParams absent = repaired_params();
  absent.labels = {7};
  result = run_pipeline(sphere, absent, {});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(result.status().message(), "label 7"));

  volume::LabelVolume empty = volume::make_phantom(volume::PhantomShape::kSphere).volume;
  // Zero bytes are label 0 whatever the voxel type.
  std::memset(empty.voxels->GetScalarPointer(), 0,
              size_t(empty.geometry.voxel_count()) * size_t(empty.voxels->GetScalarSize()));
  const std::string background = (dir / "background.nii.gz").string();
  ASSERT_THAT(volume::write_label_volume(empty, background), testing::IsOk());
  result = run_pipeline(background, repaired_params(), {});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_TRUE(absl::StrContains(result.status().message(), "only background"));

  // DICOM surfaces take their patient and study from a DICOM SEG input.
  MeshParams dicom = repaired_params();
  dicom.dicom_surfaces = true;
  result = run_pipeline(sphere, dicom, {});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(result.status().message(), "needs a DICOM SEG input"))
      << result.status();
  EXPECT_TRUE(absl::StrContains(result.status().message(), sphere)) << result.status();

  const std::atomic<bool> stop{true};
  RunContext stopped;
  stopped.stop = &stop;
  result = run_pipeline(sphere, repaired_params(), stopped);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kCancelled));
}

}  // namespace
}  // namespace labelmesh
