// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd's log lines as JSON, for log collectors: one object per line
// with the UTC time, the level, the message and, when the message names a
// job, its id.
//   {"time":"2026-01-31T12:00:00.123Z","level":"info","job_id":"…","msg":"job … queued"}
#pragma once

#include <memory>
#include <string>

#include "spdlog/formatter.h"

namespace labelmesh::server {

class JsonLogFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& message, spdlog::memory_buf_t& out) override;
  std::unique_ptr<spdlog::formatter> clone() const override;
};

// The first job id (32 hex digits after "job ") in a log message; empty if none.
std::string job_id_in(std::string_view message);

// One JSON log line, newline included.
std::string json_log_line(std::string_view time_utc, std::string_view level,
                          std::string_view message);

}  // namespace labelmesh::server
