// SPDX-License-Identifier: AGPL-3.0-or-later
// The delivery guard on the real multi-label segmentations in ../shared/data:
// every label is delivered within its tolerance, as a closed 2-manifold with
// 30-degree angles, or named in the warnings as too small to mesh. The brain
// and the frog take minutes and live in the benchmark
// (scripts/bench-labels.sh) instead; the DICOM slab is left out under the
// sanitizers, which make it several minutes.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "core/pipeline/pipeline.h"
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

class SharedVolumes : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedVolumes, EveryLabelIsWithinToleranceOrTooSmall) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  auto result = run_pipeline(testing::shared_data(GetParam()), poisson_params(), RunContext{});
  ASSERT_THAT(result, testing::IsOk());
  std::set<int32_t> too_small;
  for (const auto& warning : result->warnings) {
    EXPECT_NE(warning.reason.find("too small to mesh"), std::string::npos)
        << "label " << warning.label << ": " << warning.reason;
    EXPECT_NE(warning.reason.find("64 voxels"), std::string::npos) << warning.reason;
    too_small.insert(warning.label);
  }
  std::set<int32_t> delivered;
  for (const auto& s : result->surfaces) {
    if (!s.is_output) continue;
    SCOPED_TRACE("label " + std::to_string(s.label) + " (" + s.stage + ")");
    ASSERT_TRUE(s.fidelity.has_value());
    EXPECT_TRUE(s.fidelity->within_tolerance());
    EXPECT_TRUE(s.statistics.closed);
    EXPECT_TRUE(s.statistics.manifold);
    EXPECT_GE(s.statistics.min_angle_deg, 29.99);
    EXPECT_LE(s.statistics.max_angle_deg, 120.01);
    delivered.insert(s.label);
  }
  // Every label of the file is one or the other, never both.
  EXPECT_EQ(delivered.size() + too_small.size(), result->input.statistics.labels.size());
  for (int32_t label : too_small) EXPECT_EQ(delivered.count(label), 0u) << label;
}

INSTANTIATE_TEST_SUITE_P(Files, SharedVolumes,
                         ::testing::Values("totalseg_example_seg_fast_force_split.nii.gz",
                                           "totalseg_example_seg_mr.nii.gz",
                                           "MRIcrop-seg_converted.nii.gz",
                                           "msd_prostate_mask_00.nii", "vb-seg.mha"
#ifndef __SANITIZE_ADDRESS__
                                           ,
                                           "totalseg_example_seg_dicom.nii.gz"
#endif
                                           ));

// Brain label 8 has a groove that the mask surface bridges at its label's
// sizing and at half of it; a quarter resolves it.
TEST(SharedVolumesBrain, ANarrowGrooveGetsTheFinestMaskSurface) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshParams params = poisson_params();
  params.labels = {8};
  auto result =
      run_pipeline(testing::shared_data("iso2mesh_brain_seg_converted.nii.gz"), params, {});
  ASSERT_THAT(result, testing::IsOk());
  EXPECT_TRUE(result->warnings.empty());
  const auto output = std::find_if(result->surfaces.begin(), result->surfaces.end(),
                                   [](const SurfaceResult& s) { return s.is_output; });
  ASSERT_NE(output, result->surfaces.end());
  EXPECT_EQ(output->stage, "mask_finest");
  ASSERT_TRUE(output->fidelity.has_value());
  ASSERT_EQ(output->fidelity->attempts.size(), 3u);
  EXPECT_GT(output->fidelity->attempts[1].hausdorff_mm, 1.0);
  EXPECT_LE(output->fidelity->attempts[2].hausdorff_mm, 1.0);
  EXPECT_TRUE(output->fidelity->within_tolerance());
  EXPECT_GE(output->statistics.min_angle_deg, 29.99);
}

}  // namespace
}  // namespace labelmesh
