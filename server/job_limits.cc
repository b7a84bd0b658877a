// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/job_limits.h"

#include <algorithm>
#include <thread>

#include "absl/strings/str_cat.h"
#include "server/refusal.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

absl::StatusOr<uint64_t> output_room(const absl::StatusOr<uint64_t>& free_bytes,
                                     const ServerConfig& config) {
  if (!free_bytes.ok()) return free_bytes.status();
  const uint64_t free = *free_bytes;
  const uint64_t over_reserve =
      free > config.spool_reserve_bytes ? free - config.spool_reserve_bytes : 0;
  if (over_reserve < kLeastOutputRoom) {
    return refused(Refusal::kDiskFull,
                   absl::ResourceExhaustedError(absl::StrCat(
                       "spool disk full: ", free, " bytes free, no room over the reserve of ",
                       config.spool_reserve_bytes, " bytes for the job's results")));
  }
  return config.max_job_output_bytes > 0 ? std::min(config.max_job_output_bytes, over_reserve)
                                         : over_reserve;
}

bool wait_for_output_room(const std::function<absl::StatusOr<uint64_t>()>& free_bytes,
                          const ServerConfig& config, const std::function<bool()>& keep_waiting) {
  bool said = false;
  while (keep_waiting()) {
    auto room = output_room(free_bytes(), config);
    if (room.ok() || !is_disk_full(room.status())) {
      if (said) spdlog::info("the disk has room again; taking jobs");
      return true;
    }
    if (!said) spdlog::warn("{}; queued jobs wait for room", std::string(room.status().message()));
    said = true;
    std::this_thread::sleep_for(kRoomPollInterval);
  }
  return false;
}

absl::StatusOr<std::vector<v1::Artifact>> within_output_limit(std::vector<v1::Artifact> artifacts,
                                                              const ServerConfig& config) {
  uint64_t total = 0;
  for (const auto& artifact : artifacts) total += artifact.size_bytes();
  if (config.max_job_output_bytes > 0 && total > config.max_job_output_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the results came to ", total, " bytes, over the job's output limit of ",
                     config.max_job_output_bytes, " bytes; ask for fewer labels or formats"));
  }
  return artifacts;
}

WorkerLimits worker_limits(const ServerConfig& config, uint64_t output_file_bytes) {
  WorkerLimits limits;
  limits.memory_bytes = config.worker_memory_bytes;
  limits.threads = std::max(
      1u, std::thread::hardware_concurrency() / static_cast<unsigned>(std::max(config.workers, 1)));
  limits.cpu_seconds =
      config.worker_cpu_seconds > 0
          ? config.worker_cpu_seconds
          : static_cast<uint64_t>(2 * absl::ToDoubleSeconds(config.job_timeout)) + 1;
  limits.output_file_bytes = output_file_bytes;
  return limits;
}

}  // namespace labelmesh::server
