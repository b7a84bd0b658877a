// SPDX-License-Identifier: AGPL-3.0-or-later
// A 3D Slicer segmentation (.seg.nrrd) as one label volume: its layers
// merged, each segment under its label, with its name and colour.
#pragma once

#include <string>
#include <vector>

#include <vtkDataArray.h>
#include <vtkSmartPointer.h>

#include "absl/status/statusor.h"
#include "core/header/label_description.h"
#include "core/header/volume_header.h"
#include "core/util/run_context.h"

namespace labelmesh::volume {

struct SlicerVolume {
  // One label a voxel, in the grid's voxel order.
  vtkSmartPointer<vtkDataArray> voxels;
  // Overlapping segments kept apart (ReadLimits::separate_overlapping):
  // further label arrays like `voxels`; empty when nothing overlaps.
  std::vector<vtkSmartPointer<vtkDataArray>> more_layers;
  // One per segment, by label.
  LabelDescriptions descriptions;
};

// `values` holds header.layers values a voxel, the layer fastest (the NRRD
// order of sizes "L X Y Z"), as read from a file whose header named
// header.segments. One layer: the values are kept as they are. Several
// layers: each nonzero value becomes the label of the segment that has that
// value in that layer (SlicerSegment::description.label), uint16 when every
// label fits. Segments that overlap (a voxel set in two layers) are kept
// apart when limits.separate_overlapping: each goes whole to the first of
// voxels, more_layers[0], ... where it overlaps no segment of an earlier
// file layer, the file's layers taken in order (segment_layers.h). Errors:
// INVALID_ARGUMENT naming the file, for a layered value no segment of its
// layer has, for segments that overlap when they are not to be kept apart
// (up to 10 pairs named with their shared voxels), or for layers over
// limits.max_voxels; CANCELLED.
absl::StatusOr<SlicerVolume> merge_slicer_layers(const std::string& path,
                                                 const VolumeHeader& header, vtkDataArray* values,
                                                 const ReadLimits& limits,
                                                 const RunContext& context);

}  // namespace labelmesh::volume
