// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/merge_slicer_layers.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <vtkIntArray.h>
#include <vtkUnsignedShortArray.h>

#include "absl/container/flat_hash_map.h"
#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/segment_layers.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

// Voxels two segments both hold, per pair of segment indices (lower first).
using SharedVoxels = std::map<std::pair<int, int>, uint64_t>;

// The segment that has `value` in `layer`, by segment index.
class SegmentLookup {
 public:
  explicit SegmentLookup(const std::vector<SlicerSegment>& segments) {
    for (size_t i = 0; i < segments.size(); ++i)
      index_.emplace(key(segments[i].layer, segments[i].value), static_cast<int>(i));
  }
  // -1 when no segment of the layer has the value.
  int find(int layer, int64_t value) const {
    const auto it = index_.find(key(layer, value));
    return it == index_.end() ? -1 : it->second;
  }

 private:
  static int64_t key(int layer, int64_t value) {
    if (value < 0 || value > std::numeric_limits<int32_t>::max()) return -1;
    return int64_t{layer} << 32 | value;
  }
  absl::flat_hash_map<int64_t, int> index_;
};

// The layered voxels of `values` into one label each, counting the voxels
// that pairs of segments share.
template <typename T, typename U>
absl::Status merge_typed(const std::string& path, const T* values, int layers, size_t voxels,
                         const std::vector<SlicerSegment>& segments, U* labels,
                         SharedVoxels& shared, const RunContext& context) {
  const SegmentLookup lookup(segments);
  std::vector<int> here;  // segments set in the current voxel
  for (size_t n = 0; n < voxels; ++n) {
    if ((n & ((size_t{1} << 20) - 1)) == 0) {
      LABELMESH_RETURN_IF_ERROR(context.check_stop());
    }
    labels[n] = 0;
    here.clear();
    const T* voxel = values + n * static_cast<size_t>(layers);
    for (int layer = 0; layer < layers; ++layer) {
      if (voxel[layer] == 0) continue;
      const auto value = static_cast<int64_t>(voxel[layer]);
      const int segment = lookup.find(layer, value);
      if (segment < 0) {
        return field_error(path, "voxel data",
                           cat("layer ", layer, " holds the value ", value,
                               ", which no segment of that layer has"));
      }
      for (int other : here) ++shared[{std::min(other, segment), std::max(other, segment)}];
      if (here.empty()) labels[n] = static_cast<U>(segments[segment].description.label);
      here.push_back(segment);
    }
  }
  return absl::OkStatus();
}

// The first few pairs, names and numbers: the message must stay short.
absl::Status overlap_error(const std::string& path, const std::vector<SlicerSegment>& segments,
                           const SharedVoxels& shared) {
  constexpr size_t kPairsNamed = 10;
  auto named = [&](int i) { return cat("segment ", i, " \"", segments[i].description.name, "\""); };
  std::string pairs;
  size_t listed = 0;
  for (const auto& [pair, count] : shared) {
    if (listed++ == kPairsNamed) {
      pairs += cat(" and ", shared.size() - kPairsNamed, " more pairs");
      break;
    }
    pairs += cat(pairs.empty() ? "" : ", ", named(pair.first), " and ", named(pair.second),
                 " share ", count, " voxels");
  }
  return field_error(path, "segments",
                     cat("overlap (", pairs,
                         "); a label volume holds one label a voxel, so overlapping segments "
                         "cannot be meshed together",
                         kSeparateOverlappingHint));
}

// Overlapping segments kept apart, one file layer a group: the segments of
// one layer share no voxel, and Slicer already put the overlapping ones in
// different layers. Taken in file-layer order, each segment goes to the
// first output layer where it overlaps no segment of an earlier file layer,
// so layers that do not overlap are merged and there are never more output
// layers than file layers. Visiting a layer scans every voxel once, where a
// visit per segment would scan them once a segment.
template <typename T>
absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> separate_typed(
    const std::string& path, const T* values, const VolumeHeader& header, int vtk_type,
    const ReadLimits& limits, const RunContext& context) {
  const SegmentLookup lookup(header.segments);
  const auto layers = static_cast<size_t>(header.layers);
  const auto voxels = static_cast<size_t>(header.geometry.voxel_count());
  std::vector<int32_t> labels;
  for (const auto& segment : header.segments) labels.push_back(segment.description.label);
  return separate_segments(
      path, labels, layers, voxels, vtk_type, limits,
      [&](size_t layer, SegmentVoxelSink sink) -> absl::Status {
        for (size_t n = 0; n < voxels; ++n) {
          if ((n & ((size_t{1} << 20) - 1)) == 0) {
            LABELMESH_RETURN_IF_ERROR(context.check_stop());
          }
          const T value = values[n * layers + layer];
          if (value == 0) continue;
          const int segment = lookup.find(static_cast<int>(layer), static_cast<int64_t>(value));
          if (segment >= 0) sink(static_cast<size_t>(segment), n);
        }
        return absl::OkStatus();
      },
      context);
}

// The merged labels, and when segments overlap and limits allow it, the
// further layers that keep them apart.
template <typename Array>
absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> merge_into(const std::string& path,
                                                                      const VolumeHeader& header,
                                                                      vtkDataArray* values,
                                                                      const ReadLimits& limits,
                                                                      const RunContext& context) {
  const auto voxels = static_cast<size_t>(header.geometry.voxel_count());
  auto labels = vtkSmartPointer<Array>::New();
  labels->SetNumberOfComponents(1);
  labels->SetNumberOfTuples(static_cast<vtkIdType>(voxels));
  SharedVoxels shared;
  absl::Status status = absl::InternalError("unsupported voxel type");
  switch (values->GetDataType()) {
    vtkTemplateMacro(status =
                         merge_typed(path, static_cast<const VTK_TT*>(values->GetVoidPointer(0)),
                                     static_cast<int>(header.layers), voxels, header.segments,
                                     labels->GetPointer(0), shared, context));
  }
  if (!status.ok()) return status;
  if (shared.empty()) return std::vector<vtkSmartPointer<vtkDataArray>>{labels};
  if (!limits.separate_overlapping) return overlap_error(path, header.segments, shared);
  const int vtk_type = labels->GetDataType();
  labels = nullptr;  // its memory goes to the layers
  absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> layers =
      absl::InternalError("unsupported voxel type");
  switch (values->GetDataType()) {
    vtkTemplateMacro(layers =
                         separate_typed(path, static_cast<const VTK_TT*>(values->GetVoidPointer(0)),
                                        header, vtk_type, limits, context));
  }
  return layers;
}

LabelDescriptions descriptions_by_label(const std::vector<SlicerSegment>& segments) {
  LabelDescriptions descriptions;
  for (const auto& segment : segments) descriptions.push_back(segment.description);
  std::sort(descriptions.begin(), descriptions.end(),
            [](const auto& a, const auto& b) { return a.label < b.label; });
  return descriptions;
}

}  // namespace

absl::StatusOr<SlicerVolume> merge_slicer_layers(const std::string& path,
                                                 const VolumeHeader& header, vtkDataArray* values,
                                                 const ReadLimits& limits,
                                                 const RunContext& context) {
  const auto expected = header.geometry.voxel_count() * header.layers;
  if (values->GetNumberOfComponents() != 1 || values->GetNumberOfTuples() != expected) {
    return field_error(path, "voxel data", "does not hold one value per voxel and layer");
  }
  SlicerVolume volume;
  volume.descriptions = descriptions_by_label(header.segments);
  if (header.layers == 1) {
    volume.voxels = values;
    return volume;
  }
  int32_t most = 0;
  for (const auto& segment : header.segments) most = std::max(most, segment.description.label);
  LABELMESH_ASSIGN_OR_RETURN(
      auto merged, most <= std::numeric_limits<uint16_t>::max()
                       ? merge_into<vtkUnsignedShortArray>(path, header, values, limits, context)
                       : merge_into<vtkIntArray>(path, header, values, limits, context));
  volume.voxels = merged.front();
  volume.more_layers.assign(merged.begin() + 1, merged.end());
  return volume;
}

}  // namespace labelmesh::volume
