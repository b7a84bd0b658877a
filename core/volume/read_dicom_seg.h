// SPDX-License-Identifier: AGPL-3.0-or-later
// Reads a DICOM Segmentation object (BINARY or FRACTIONAL) into a label
// volume: segment number n becomes label n, and each segment's label, colour
// and coded meaning become the label's description.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/header/volume_header.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// The header and grid are checked first (header/dicom_seg_grid.h), then DCMTK's
// dcmseg reads the segments and the pixel data. A FRACTIONAL pixel counts as
// inside when value / Maximum Fractional Value >= limits.fractional_threshold.
// Segments that overlap are an error naming them and the voxels they share,
// unless limits.separate_overlapping: then each segment goes whole, in
// segment-number order, to the first image (voxels, then more_layers) where
// none of its voxels is taken (segment_layers.h); the images together count
// against limits.max_voxels, an INVALID_ARGUMENT naming the file beyond it.
absl::StatusOr<LabelVolume> read_dicom_seg(const std::string& path, const ReadLimits& limits,
                                           const RunContext& context);

}  // namespace labelmesh::volume
