// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks of an upload before it becomes a job: the spec, then the bytes, then
// the volume's header with our own validation, before any library reader.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/header/image_geometry.h"
#include "core/job/mesh_params.h"
#include "labelmesh/v1/service.pb.h"
#include "server/server_config.h"

namespace labelmesh::server {

// The extension the upload is stored under (".nii.gz", ...), from the formats
// held in one file. INVALID_ARGUMENT naming spec.file_name otherwise.
absl::StatusOr<std::string> upload_extension(const std::string& file_name);

// The job's options as the pipeline reads them (the one parse of them in the
// server), or INVALID_ARGUMENT naming the spec field or option at fault; a
// size over the server's limit is marked too_large.
absl::StatusOr<MeshParams> check_spec(const v1::JobSpec& spec, const ServerConfig& config);

// The stored upload, before it becomes a job: its header, with the job's
// voxel limit; the least memory a worker needs for it, against the worker
// limit (0: none); then every compressed byte, checksum included. The
// volume must hold its voxels itself: a header naming another file is
// refused. INVALID_ARGUMENT; messages name the file "upload".
// Returns the header's geometry, for the checks of options against the grid.
absl::StatusOr<volume::ImageGeometry> check_uploaded_volume(const std::string& path,
                                                            uint64_t max_voxels,
                                                            uint64_t worker_memory_bytes);

}  // namespace labelmesh::server
