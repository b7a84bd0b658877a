// SPDX-License-Identifier: AGPL-3.0-or-later
// The limits a job runs under, from the server's config: the worker
// process's memory, CPU time, threads and largest file, and the most its
// results may come to. The same for a local worker pool and a cluster worker.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "labelmesh/v1/service.pb.h"
#include "server/server_config.h"
#include "server/worker_process.h"

namespace labelmesh::server {

// Less room than this over the reserve and a job does not start.
inline constexpr uint64_t kLeastOutputRoom = uint64_t{1} << 20;
// How often workers waiting for room on a full spool disk look again.
inline constexpr std::chrono::seconds kRoomPollInterval{1};

// The largest file a job starting now may write, given the free bytes where
// it writes: its output limit, or the free space over the reserve if that is
// less. RESOURCE_EXHAUSTED when under kLeastOutputRoom is left.
absl::StatusOr<uint64_t> output_room(const absl::StatusOr<uint64_t>& free_bytes,
                                     const ServerConfig& config);

// Whether output_room's error is a disk with no room over the reserve (the
// job can wait), not another error (which fails it).
inline bool is_disk_full(const absl::Status& status) {
  return status.code() == absl::StatusCode::kResourceExhausted;
}

// Returns true once `free_bytes` leaves room for a job's results (or fails
// otherwise: the job then meets that error), looking again every
// kRoomPollInterval and logging once while the disk is full; false when
// `keep_waiting` says stop first.
bool wait_for_output_room(const std::function<absl::StatusOr<uint64_t>()>& free_bytes,
                          const ServerConfig& config, const std::function<bool()>& keep_waiting);

// The results, or RESOURCE_EXHAUSTED if together they are over the output
// limit.
absl::StatusOr<std::vector<v1::Artifact>> within_output_limit(std::vector<v1::Artifact> artifacts,
                                                              const ServerConfig& config);

// A worker process's limits; each of config.workers jobs meshes on its share
// of the cores.
WorkerLimits worker_limits(const ServerConfig& config, uint64_t output_file_bytes);

}  // namespace labelmesh::server
