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
#include <set>
#include <string>

#include "absl/strings/match.h"
#include "core/pipeline/write_results.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

namespace fs = std::filesystem;

std::string write_phantom(const fs::path& dir, volume::PhantomShape shape) {
  const auto path = (dir / "phantom.nii.gz").string();
  const auto status = volume::write_label_volume(volume::make_phantom(shape).volume, path);
  EXPECT_TRUE(status.ok()) << status;
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
  ASSERT_TRUE(result.ok()) << result.status();
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
  ASSERT_TRUE(write_results(*result, params, out.string(), {}).ok());
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

TEST(Pipeline, BadRequestsGetTheirOwnCodesNamingTheCause) {
  const fs::path dir = testing::scratch_dir("pipeline_errors");
  const std::string missing = (dir / "no-such.nii.gz").string();
  auto result = run_pipeline(missing, repaired_params(), {});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(absl::StrContains(result.status().message(), "no-such.nii.gz"));

  const std::string sphere = write_phantom(dir, volume::PhantomShape::kSphere);
  MeshParams absent = repaired_params();
  absent.labels = {7};
  result = run_pipeline(sphere, absent, {});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(absl::StrContains(result.status().message(), "label 7"));

  volume::LabelVolume empty = volume::make_phantom(volume::PhantomShape::kSphere).volume;
  // Zero bytes are label 0 whatever the voxel type.
  std::memset(empty.voxels->GetScalarPointer(), 0,
              size_t(empty.geometry.voxel_count()) * size_t(empty.voxels->GetScalarSize()));
  const std::string background = (dir / "background.nii.gz").string();
  ASSERT_TRUE(volume::write_label_volume(empty, background).ok());
  result = run_pipeline(background, repaired_params(), {});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(absl::StrContains(result.status().message(), "only background"));

  const std::atomic<bool> stop{true};
  RunContext stopped;
  stopped.stop = &stop;
  result = run_pipeline(sphere, repaired_params(), stopped);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace labelmesh
