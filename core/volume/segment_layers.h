// SPDX-License-Identifier: AGPL-3.0-or-later
// Overlapping segments kept apart (ReadLimits::separate_overlapping): each
// segment is placed whole in the first of several label images where none of
// its voxels is taken yet, a first-fit layering like greedy graph colouring
// of the segments' overlap graph. Used by the DICOM SEG reader and the 3D
// Slicer layer merge, the two inputs whose segments can overlap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include <vtkDataArray.h>
#include <vtkSmartPointer.h>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "core/header/volume_header.h"
#include "core/util/run_context.h"

namespace labelmesh::volume {

// At most this many layers; a uint64_t mask per segment tracks them.
inline constexpr int kMostSegmentLayers = 64;

// Appended to the refusal of overlapping segments in the default mode.
inline constexpr char kSeparateOverlappingHint[] =
    "; --overlapping separate meshes each segment on its own";

// Receives one voxel of one segment: its segment index (into `labels`) and
// its voxel index in the grid (0 to voxels - 1).
using SegmentVoxelSink = absl::FunctionRef<void(size_t segment, uint64_t voxel)>;
// Sends every voxel of every segment of one group to the sink; a segment
// belongs to one group and the segments of one group share no voxel (a
// DICOM SEG segment alone, a Slicer file layer). Returns an error to stop,
// e.g. CANCELLED from its own stop checks.
using SegmentGroupVisitor = absl::FunctionRef<absl::Status(size_t group, SegmentVoxelSink sink)>;

// Lays out segments with labels `labels[s]` in label images of `voxels`
// voxels each, of VTK type `vtk_type` (VTK_UNSIGNED_SHORT or VTK_INT).
// Groups are visited in order 0..groups-1, each twice (check, then write):
// a segment goes to the first image where none of its voxels is taken by a
// segment of an earlier group, so the result depends only on the group
// order. Returns the images, at least one (the first may be empty);
// segments without voxels are in none. Errors, INVALID_ARGUMENT naming
// `path`: more than kMostSegmentLayers images needed, or images × voxels
// over limits.max_voxels (checked before each image is allocated);
// whatever `visit` returns.
absl::StatusOr<std::vector<vtkSmartPointer<vtkDataArray>>> separate_segments(
    std::string_view path, const std::vector<int32_t>& labels, size_t groups, uint64_t voxels,
    int vtk_type, const ReadLimits& limits, SegmentGroupVisitor visit, const RunContext& context);

}  // namespace labelmesh::volume
