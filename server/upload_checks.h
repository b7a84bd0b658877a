// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks of an upload before it becomes a job: the spec, then the bytes, then
// the volume's header with our own validation, before any library reader.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "labelmesh/v1/service.pb.h"
#include "server/server_config.h"

namespace labelmesh::server {

// The extension the upload is stored under (".nii.gz", ...), from the formats
// held in one file. INVALID_ARGUMENT naming spec.file_name otherwise.
absl::StatusOr<std::string> upload_extension(const std::string& file_name);

// INVALID_ARGUMENT naming the spec field or option at fault.
absl::Status check_spec(const v1::JobSpec& spec, const ServerConfig& config);

// The header of the stored upload, with the job's voxel limit. The volume
// must hold its voxels itself: a header naming another file is refused.
// Messages name the file "upload".
absl::Status check_uploaded_volume(const std::string& path, uint64_t max_voxels);

}  // namespace labelmesh::server
