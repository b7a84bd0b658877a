// SPDX-License-Identifier: AGPL-3.0-or-later
// Reads a label volume from any supported file, in patient (LPS) space.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/header/volume_header.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// Checks the header with check_volume_header(), then reads the voxels: VTK's
// readers for NIfTI and VTI; our bounded block reader for INR (VTK 9.1 has no
// INR reader), NRRD (VTK's drops the orientation and flips LAS data) and
// MetaImage (VTK's MetaIO stops at CompressedDataSize, which real files
// understate: it loses the end of frogtissue.zraw).
// Voxels of type uint32, (u)int64 and float are converted to int32; real
// values must be whole numbers and every label must fit in int32. A NRRD
// with 3D Slicer segment keys (.seg.nrrd) gets its segments' names and
// colours, its layers merged into one label a voxel (merge_slicer_layers.h).
// Errors: NOT_FOUND (no file), INVALID_ARGUMENT naming the file and the field
// or data at fault, CANCELLED.
absl::StatusOr<LabelVolume> read_label_volume(const std::string& path, const ReadLimits& limits,
                                              const RunContext& context);

}  // namespace labelmesh::volume
