// SPDX-License-Identifier: AGPL-3.0-or-later
// Following a remote job to its end and fetching its results: shared by
// `submit`, `watch` and `fetch`.
#pragma once

#include <optional>
#include <string>

#include "absl/status/status.h"
#include "client/server_connection.h"
#include "labelmesh/v1/service.pb.h"

namespace labelmesh::client {

struct FollowOptions {
  // One JSON line per event on stdout instead of progress on stderr.
  bool json = false;
  // How long to keep reconnecting while the server is unreachable.
  std::chrono::seconds reconnect_for{120};
};

// Watches until the job ends. Returns the final Job (from GetJob), or the
// call's error when the server stays unreachable or refuses.
absl::StatusOr<v1::Job> follow_job(const ServerConnection& connection, const std::string& job_id,
                                   const FollowOptions& options);

// The exit code for an ended job: 0 succeeded, 3 bad input, 4 otherwise.
int exit_code_for_job(const v1::Job& job);

// Fetches every artifact (or the one named) into `out_dir`, checking each
// size and SHA-256. Returns how many files were written.
absl::StatusOr<int> fetch_artifacts(const ServerConnection& connection, const std::string& job_id,
                                    const std::string& out_dir,
                                    const std::optional<std::string>& only = std::nullopt);

// A grpc::Status as an absl::Status, message prefixed with the code's name.
absl::Status from_grpc(const grpc::Status& status);

// Exit code for a failed call: 5 when unreachable or refused, else by code.
int exit_code_for_call(const absl::Status& status);

}  // namespace labelmesh::client
