// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/audit_log.h"

#include <cerrno>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "server/json_text.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

std::string audit_json(const AuditEntry& entry, const std::string& time_utc) {
  std::string line =
      absl::StrCat("{\"time\":", json_string(time_utc), ",\"event\":", json_string(entry.event));
  auto field = [&line](const char* name, const std::string& value) {
    if (!value.empty()) absl::StrAppend(&line, ",\"", name, "\":", json_string(value));
  };
  field("job_id", entry.job_id);
  field("identity", entry.identity);
  field("peer", entry.peer);
  field("call", entry.call);
  field("code", entry.code);
  field("reason", entry.reason);
  return line + "}";
}

absl::StatusOr<std::unique_ptr<AuditLog>> AuditLog::open(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "ae");
  if (file == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("--audit-log: cannot open ", path, ": ", std::strerror(errno)));
  }
  return std::unique_ptr<AuditLog>(new AuditLog(file));
}

AuditLog::~AuditLog() { std::fclose(file_); }

void AuditLog::record(const AuditEntry& entry) {
  const std::string time =
      absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone());
  const std::string line = audit_json(entry, time) + "\n";
  absl::MutexLock lock(&mutex_);
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size() || std::fflush(file_) != 0) {
    spdlog::error("audit log: a line could not be written: {}", std::strerror(errno));
  }
}

}  // namespace labelmesh::server
