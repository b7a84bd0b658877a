// SPDX-License-Identifier: AGPL-3.0-or-later
// The audit log: one JSON line per accepted, refused, deleted and expired
// job and per failed authentication, with UTC time, the client identity and
// host. It never holds text from an upload: a refusal names its reason code,
// not the message (which can quote header fields).
#pragma once

#include <cstdio>
#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"

namespace labelmesh::server {

// One event. Every field starts empty, so an entry names only those it has.
struct AuditEntry {
  // accepted, refused, deleted, expired, unauthenticated.
  std::string event{};
  std::string job_id{};
  std::string identity{};
  // The client host, e.g. "ipv4:10.0.0.7".
  std::string peer{};
  // The RPC, e.g. "Submit".
  std::string call{};
  // A gRPC status code name when refused, e.g. "INVALID_ARGUMENT".
  std::string code{};
  // A short reason code, e.g. "bad_volume", "queue_full".
  std::string reason{};
};

// One line of JSON (no newline) for `entry`, stamped `time_utc`.
std::string audit_json(const AuditEntry& entry, const std::string& time_utc);

class AuditLog {
 public:
  // Appends to `path`; its directory must exist.
  static absl::StatusOr<std::unique_ptr<AuditLog>> open(const std::string& path);
  ~AuditLog();

  void record(const AuditEntry& entry);

 private:
  explicit AuditLog(std::FILE* file) : file_(file) {}
  absl::Mutex mutex_;
  // Lines are written whole, one writer at a time.
  std::FILE* const file_ ABSL_PT_GUARDED_BY(mutex_);
};

}  // namespace labelmesh::server
