// SPDX-License-Identifier: AGPL-3.0-or-later
// First-fit layering of overlapping segments: where each segment goes, and
// the bounds on how many layers there may be.
#include "core/volume/segment_layers.h"
#include "support/status_matchers.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/strings/match.h"

namespace labelmesh::volume {
namespace {

// Segments as lists of voxel indices, one segment a group.
struct Segments {
  std::vector<std::vector<uint64_t>> voxels;

  absl::Status visit(size_t group, SegmentVoxelSink sink) const {
    for (uint64_t voxel : voxels[group]) sink(group, voxel);
    return absl::OkStatus();
  }
};

absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> separate(
    const Segments& segments, uint64_t voxels, const ReadLimits& limits = {},
    const RunContext& context = {}) {
  std::vector<int32_t> labels;
  for (size_t s = 0; s < segments.voxels.size(); ++s) labels.push_back(static_cast<int32_t>(s + 1));
  return separate_segments(
      "test.dcm", labels, segments.voxels.size(), voxels, VTK_UNSIGNED_SHORT, limits,
      [&](size_t group, SegmentVoxelSink sink) { return segments.visit(group, sink); }, context);
}

// The layer each label lies in, -1 where none; fails if it is in two.
std::vector<int> layer_of_labels(const std::vector<vtkSmartPointer<vtkDataArray>>& layers,
                                 int labels) {
  std::vector<int> where(labels + 1, -1);
  for (size_t k = 0; k < layers.size(); ++k) {
    for (vtkIdType i = 0; i < layers[k]->GetNumberOfTuples(); ++i) {
      const int label = static_cast<int>(layers[k]->GetTuple1(i));
      if (label == 0) continue;
      EXPECT_TRUE(where[label] == -1 || where[label] == static_cast<int>(k)) << label;
      where[label] = static_cast<int>(k);
    }
  }
  return where;
}

TEST(SegmentLayers, EachSegmentGoesToTheFirstLayerWhereItFits) {
  // 1 and 2 share voxel 2; 3 overlaps only 2, 4 overlaps 1 and 2, 5 nothing.
  const Segments segments{{{0, 1, 2}, {2, 3, 4}, {4, 5}, {1, 3, 6}, {7}}};
  auto layers = separate(segments, 8);
  ASSERT_THAT(layers, testing::IsOk());
  ASSERT_EQ(layers->size(), 3u);
  EXPECT_EQ(layer_of_labels(*layers, 5), (std::vector<int>{-1, 0, 1, 0, 2, 0}));
  // Every segment whole: its voxels all carry its label in its layer.
  const auto where = layer_of_labels(*layers, 5);
  for (size_t s = 0; s < segments.voxels.size(); ++s) {
    for (uint64_t voxel : segments.voxels[s]) {
      EXPECT_EQ((*layers)[where[s + 1]]->GetTuple1(static_cast<vtkIdType>(voxel)), double(s + 1))
          << "segment " << s + 1 << " voxel " << voxel;
    }
  }
}

TEST(SegmentLayers, DisjointSegmentsShareOneLayer) {
  auto layers = separate(Segments{{{0, 1}, {}, {2, 3}}}, 4);
  ASSERT_THAT(layers, testing::IsOk());
  ASSERT_EQ(layers->size(), 1u);
  EXPECT_EQ(layer_of_labels(*layers, 3), (std::vector<int>{-1, 0, -1, 0}));
}

TEST(SegmentLayers, AtMost64Layers) {
  Segments all_at_one_voxel;
  all_at_one_voxel.voxels.assign(kMostSegmentLayers + 1, std::vector<uint64_t>{0});
  auto layers = separate(all_at_one_voxel, 1);
  ASSERT_FALSE(layers.ok());
  EXPECT_THAT(layers, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(layers.status().message(), "test.dcm")) << layers.status();
  EXPECT_TRUE(absl::StrContains(layers.status().message(), "more than 64 layers"))
      << layers.status();
  all_at_one_voxel.voxels.pop_back();
  layers = separate(all_at_one_voxel, 1);
  ASSERT_THAT(layers, testing::IsOk());
  EXPECT_EQ(layers->size(), 64u);
}

TEST(SegmentLayers, LayersTimesVoxelsStayWithinTheVoxelLimit) {
  const Segments overlapping{{{0, 1}, {1, 2}, {2, 3}, {0, 3}}};
  ReadLimits limits;
  limits.max_voxels = 2 * 10;
  auto layers = separate(overlapping, 10, limits);
  ASSERT_THAT(layers, testing::IsOk());
  EXPECT_EQ(layers->size(), 2u);
  limits.max_voxels = 2 * 10 - 1;
  layers = separate(overlapping, 10, limits);
  ASSERT_FALSE(layers.ok());
  EXPECT_TRUE(absl::StrContains(layers.status().message(), "2 layers of 10 voxels"))
      << layers.status();
}

TEST(SegmentLayers, AStopRequestEndsTheLayout) {
  std::atomic<bool> stop{true};
  RunContext context;
  context.stop = &stop;
  auto layers = separate(Segments{{{0}}}, 1, ReadLimits{}, context);
  EXPECT_THAT(layers, testing::StatusIs(absl::StatusCode::kCancelled));
}

}  // namespace
}  // namespace labelmesh::volume
