// SPDX-License-Identifier: AGPL-3.0-or-later
// Where three labels meet the net smooths the surface as anywhere else;
// only around a small label does it hold the junction curves sharp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "core/conforming/label_interfaces.h"
#include "core/pipeline/label_net_surfaces.h"
#include "core/pipeline/pipeline.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom_grid.h"
#include "support/label_volumes.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

using geometry::Vec3;

const SurfaceResult* output_of(const MeshResult& result, int32_t label) {
  for (const auto& s : result.surfaces)
    if (s.label == label && s.is_output) return &s;
  return nullptr;
}

// A ball of radius 12 voxels on 3 mm voxels cut by an oblique gap one voxel
// wide into labels 1 and 2, with a cube of label 3, `edge` voxels along each
// axis, across the gap at the ball's centre.
volume::LabelVolume ball_with_a_cube_across_its_gap(int64_t edge) {
  constexpr double kVoxel = 3;
  const Vec3 across = geometry::scale(Vec3{1, 1, 0.6}, 1 / std::sqrt(2.36));
  auto volume = volume::rasterise(volume::centred_grid({31, 31, 31}, {kVoxel, kVoxel, kVoxel},
                                                       testing::kIdentityDirection, {0, 0, 0}),
                                  [&](const Vec3& p) {
                                    if (geometry::norm(p) > 12 * kVoxel) return 0;
                                    const double along = geometry::dot(p, across);
                                    return along < -0.5 * kVoxel ? 1 : along > 0.5 * kVoxel ? 2 : 0;
                                  });
  const auto& d = volume.geometry.dims;
  auto* labels = static_cast<uint8_t*>(volume.voxels->GetScalarPointer());
  const int64_t first = d[0] / 2 - edge / 2;
  for (int64_t k = first; k < first + edge; ++k)
    for (int64_t j = first; j < first + edge; ++j)
      for (int64_t i = first; i < first + edge; ++i) labels[(k * d[1] + j) * d[0] + i] = 3;
  return volume;
}

// A label of 27 voxels keeps the junction curves around it, and its volume;
// around one of 512 voxels no point is held to a curve.
TEST(JunctionBands, SmallLabelsKeepTheirJunctionCurves) {
  const auto small = ball_with_a_cube_across_its_gap(3);
  conforming::InterfaceFigures figures;
  conforming::label_interfaces(small, {}, net_interface_params(NetOptions{}), figures);
  EXPECT_GT(figures.curve_points, 0u);
  auto result = run_pipeline_on_volume(small, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  for (const int32_t label : {1, 2, 3}) {
    const auto* s = output_of(*result, label);
    ASSERT_NE(s, nullptr) << label;
    EXPECT_EQ(s->stage, "net") << label;
    EXPECT_TRUE(s->fidelity->within_tolerance()) << label;
  }

  conforming::label_interfaces(ball_with_a_cube_across_its_gap(8), {},
                               net_interface_params(NetOptions{}), figures);
  EXPECT_GT(figures.junction_points, 100u);
  EXPECT_EQ(figures.curve_points, 0u);
}

// TotalSegmentator's 3 mm whole-body segmentation: organs touch one another
// nearly everywhere, across gaps a voxel wide and along thin tissues. Held to
// the junction curves there, the surfaces kept the voxels' steps and thin
// triangles (docs/benchmarks.md); smoothed as anywhere else, every label
// stays within the voxel tolerance.
TEST(JunctionBands, TouchingOrgansOnThreeMillimetresAreSmoothWhereTheyMeet) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("totalseg_example_seg_fast_force_split.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  std::vector<double> shares;
  double smallest_angle = 180;
  size_t delivered = 0;
  for (const auto& s : result->surfaces) {
    if (!s.is_output) continue;
    ++delivered;
    EXPECT_TRUE(s.fidelity->within_tolerance()) << s.label;
    smallest_angle = std::min(smallest_angle, s.statistics.min_angle_deg);
    const auto* label = result->input.statistics.find(s.label);
    if (label != nullptr && label->voxels >= 1000 && s.axis_aligned_share)
      shares.push_back(*s.axis_aligned_share);
  }
  EXPECT_EQ(delivered, 61u);
  ASSERT_EQ(shares.size(), 41u);
  std::nth_element(shares.begin(), shares.begin() + 20, shares.end());
  EXPECT_LT(shares[20], 0.11);
  EXPECT_GT(smallest_angle, 12);
}

}  // namespace
}  // namespace labelmesh
