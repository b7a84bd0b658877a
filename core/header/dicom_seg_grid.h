// SPDX-License-Identifier: AGPL-3.0-or-later
// Where the frames of a DICOM Segmentation land in one regular grid in
// patient space, from its parsed header alone: what a SEG can be meshed
// from, and what it cannot (no 3D patient geometry, a SOP class we do not
// read, frames off any regular grid).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/header/dicom_seg_header.h"
#include "core/header/image_geometry.h"
#include "core/header/volume_header.h"

namespace labelmesh::volume {

inline constexpr std::string_view kSegmentationStorage = "1.2.840.10008.5.1.4.1.1.66.4";
inline constexpr std::string_view kLabelMapSegmentationStorage = "1.2.840.10008.5.1.4.1.1.66.7";

struct DicomSegGrid {
  // dims: columns x rows x slices; axis 0 along a row, axis 1 down the
  // columns, axis 2 along the slice normal (row x column direction).
  ImageGeometry geometry;
  // Each stored frame's slice index along axis 2.
  std::vector<int64_t> frame_slice;
};

// A SEG stores only the frames that hold something, so slices may be
// missing. The slice spacing is Spacing Between Slices when given, else the
// smallest gap between frames (else, for one slice, Slice Thickness); every
// frame must lie on that grid within 1 % of the spacing and share the first
// frame's in-plane origin. The grid's voxels are bounded by limits.max_voxels.
// Errors are INVALID_ARGUMENT naming the file and what is wrong.
absl::StatusOr<DicomSegGrid> dicom_seg_grid(std::string_view path,
                                            const internal::DicomSegHeader& header,
                                            const ReadLimits& limits);

}  // namespace labelmesh::volume
