// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/segment_layers.h"

#include <algorithm>
#include <bit>
#include <limits>

#include <vtkIntArray.h>
#include <vtkUnsignedShortArray.h>

#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

template <typename Array>
absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> separate_typed(
    std::string_view path, const std::vector<int32_t>& labels, size_t groups, uint64_t voxels,
    const ReadLimits& limits, SegmentGroupVisitor visit, const RunContext& context) {
  using Label = typename Array::ValueType;
  std::vector<vtkSmartPointer<Array>> layers;
  std::vector<Label*> layer_voxels;
  // Bounded before allocating: the layers together count against the
  // job's voxel limit, as the layers of a Slicer file do.
  auto add_layer = [&]() -> absl::Status {
    const uint64_t count = layers.size() + 1;
    if (count > kMostSegmentLayers) {
      return field_error(path, "segments",
                         cat("overlap so that keeping them apart needs more than ",
                             kMostSegmentLayers, " layers"));
    }
    if (voxels > limits.max_voxels / count) {
      return field_error(path, "segments",
                         cat("overlap; kept apart they need ", count, " layers of ", voxels,
                             " voxels, which exceeds the limit of ", limits.max_voxels, " voxels"));
    }
    auto layer = vtkSmartPointer<Array>::New();
    layer->SetNumberOfComponents(1);
    layer->SetNumberOfTuples(static_cast<vtkIdType>(voxels));
    Label* data = layer->GetPointer(0);
    std::fill(data, data + voxels, Label{0});
    layers.push_back(layer);
    layer_voxels.push_back(data);
    return absl::OkStatus();
  };
  LABELMESH_RETURN_IF_ERROR(add_layer());

  const size_t segments = labels.size();
  // Per segment: the layers where one of its voxels is taken, bit k for
  // layer k; then the layer it goes to.
  std::vector<uint64_t> blocked(segments, 0);
  std::vector<int> placed(segments, -1);
  std::vector<size_t> in_group;  // segments seen in the current group
  bool out_of_range = false;
  for (size_t group = 0; group < groups; ++group) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    in_group.clear();
    const uint64_t existing =
        layers.size() >= 64 ? ~uint64_t{0} : (uint64_t{1} << layers.size()) - 1;
    absl::Status status = visit(group, [&](size_t segment, uint64_t voxel) {
      if (segment >= segments || voxel >= voxels) {
        out_of_range = true;
        return;
      }
      if (placed[segment] == -1) {
        placed[segment] = -2;  // seen, not placed yet
        in_group.push_back(segment);
      }
      for (uint64_t free = existing & ~blocked[segment]; free != 0; free &= free - 1) {
        const int k = std::countr_zero(free);
        if (layer_voxels[k][voxel] != 0) blocked[segment] |= uint64_t{1} << k;
      }
    });
    if (!status.ok()) return status;
    if (out_of_range) return absl::InternalError("a segment voxel outside the grid");
    for (size_t segment : in_group) {
      const int k = std::countr_one(blocked[segment]);
      if (k == static_cast<int>(layers.size())) {
        LABELMESH_RETURN_IF_ERROR(add_layer());
      }
      placed[segment] = k;
    }
    if (in_group.empty()) continue;
    status = visit(group, [&](size_t segment, uint64_t voxel) {
      if (segment >= segments || voxel >= voxels || placed[segment] < 0) {
        out_of_range = true;
        return;
      }
      layer_voxels[placed[segment]][voxel] = static_cast<Label>(labels[segment]);
    });
    if (!status.ok()) return status;
    if (out_of_range) return absl::InternalError("a segment's voxels changed between visits");
  }
  return std::vector<vtkSmartPointer<vtkDataArray>>(layers.begin(), layers.end());
}

}  // namespace

absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> separate_segments(
    std::string_view path, const std::vector<int32_t>& labels, size_t groups, uint64_t voxels,
    int vtk_type, const ReadLimits& limits, SegmentGroupVisitor visit, const RunContext& context) {
  if (vtk_type == VTK_UNSIGNED_SHORT) {
    for (int32_t label : labels) {
      if (label < 0 || label > std::numeric_limits<uint16_t>::max())
        return absl::InternalError("a segment label does not fit the uint16 layers");
    }
    return separate_typed<vtkUnsignedShortArray>(path, labels, groups, voxels, limits, visit,
                                                 context);
  }
  if (vtk_type == VTK_INT)
    return separate_typed<vtkIntArray>(path, labels, groups, voxels, limits, visit, context);
  return absl::InternalError("segment layers are uint16 or int32");
}

}  // namespace labelmesh::volume
