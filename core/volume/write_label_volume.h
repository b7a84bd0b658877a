// SPDX-License-Identifier: AGPL-3.0-or-later
// Writes a label volume in any format labelmesh reads, keeping its placement.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// The format follows the extension (.nii, .nii.gz, .mha, .mhd + .raw, .nrrd,
// .nhdr + .raw, .inr, .inr.gz, .vti). NIfTI gets sform and qform in RAS; INR
// cannot store an oblique grid and refuses one. Errors: INVALID_ARGUMENT for
// an unknown extension or an unrepresentable volume, INTERNAL on I/O failure.
absl::Status write_label_volume(const LabelVolume& volume, const std::string& path);

}  // namespace labelmesh::volume
