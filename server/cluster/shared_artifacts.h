// SPDX-License-Identifier: AGPL-3.0-or-later
// Uploads and results in one directory that every frontend and worker
// mounts (a ReadWriteMany volume or NFS). A file appears whole or not at
// all: it is written under a hidden name, synced, then renamed. Each
// attempt at a job writes its own directory, so a worker the queue gave up
// on never mixes its files with the next worker's; once the job's final
// state is set, the other attempts' directories go.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace labelmesh::cluster {

class SharedArtifacts {
 public:
  // Uses `root`, creating it and its uploads/ and jobs/ directories.
  // Errors: INTERNAL naming the directory.
  static absl::StatusOr<SharedArtifacts> open(const std::string& root);

  const std::string& root() const { return root_; }
  // jobs/<job id>, under the root: the job's record, input and attempts.
  std::string job_dir(const std::string& job_id) const;
  // jobs/<job id>/out-<n> (the layout the worker program expects), under the root.
  std::string attempt_dir(const std::string& job_id, uint32_t attempt) const;
  // Bytes an unprivileged writer may still use under the root.
  absl::StatusOr<uint64_t> free_bytes() const;

  // Writes `bytes` to `relative` (a path under the root) so that readers
  // see the whole file or none. Errors: INVALID_ARGUMENT for a path that is
  // absolute or leaves the root; RESOURCE_EXHAUSTED for a full disk;
  // INTERNAL.
  absl::Status put(std::string_view relative, std::string_view bytes) const;

  // The bytes of `relative`. Errors: INVALID_ARGUMENT as for put;
  // NOT_FOUND.
  absl::StatusOr<std::string> get(std::string_view relative) const;

  // Removes every attempt directory of `job_id` except `kept`'s; how many
  // went.
  absl::StatusOr<size_t> remove_other_attempts(const std::string& job_id, uint32_t kept) const;
  // Removes the job's directory and everything in it.
  void remove_job(const std::string& job_id) const;

 private:
  explicit SharedArtifacts(std::string root) : root_(std::move(root)) {}
  absl::StatusOr<std::string> resolve(std::string_view relative) const;
  std::string root_;
};

}  // namespace labelmesh::cluster
