// SPDX-License-Identifier: AGPL-3.0-or-later
// One parser per file format; check_volume_header() picks among them.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/header/volume_header.h"

namespace labelmesh::volume::internal {

// NIfTI-1 and NIfTI-2, single file (.nii, .nii.gz).
absl::StatusOr<VolumeHeader> check_nifti_header(const std::string& path, bool gzip,
                                                const ReadLimits& limits);
// MetaImage: .mha (attached data) and .mhd (detached data file).
absl::StatusOr<VolumeHeader> check_metaimage_header(const std::string& path,
                                                    const ReadLimits& limits);
// NRRD: .nrrd (attached) and .nhdr (detached data file).
absl::StatusOr<VolumeHeader> check_nrrd_header(const std::string& path, const ReadLimits& limits);
// INRIMAGE-4 (.inr, .inr.gz).
absl::StatusOr<VolumeHeader> check_inr_header(const std::string& path, bool gzip,
                                              const ReadLimits& limits);
// VTK XML image data (.vti).
absl::StatusOr<VolumeHeader> check_vti_header(const std::string& path, const ReadLimits& limits);
// DICOM Segmentation objects (.dcm): our own walk of the header, then the
// grid its frames land on (dicom_seg_grid.h).
absl::StatusOr<VolumeHeader> check_dicom_seg_volume_header(const std::string& path,
                                                           const ReadLimits& limits);

}  // namespace labelmesh::volume::internal
