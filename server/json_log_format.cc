// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/json_log_format.h"

#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "server/json_text.h"
#include "server/spool.h"

namespace labelmesh::server {

std::string job_id_in(std::string_view message) {
  constexpr std::string_view kJob = "job ";
  for (size_t at = message.find(kJob); at != std::string_view::npos;
       at = message.find(kJob, at + 1)) {
    const std::string_view candidate = message.substr(at + kJob.size(), 32);
    if (is_job_id(candidate)) return std::string(candidate);
  }
  return "";
}

std::string json_log_line(std::string_view time_utc, std::string_view level,
                          std::string_view message) {
  std::string line =
      absl::StrCat("{\"time\":", json_string(time_utc), ",\"level\":", json_string(level));
  if (const std::string job = job_id_in(message); !job.empty()) {
    absl::StrAppend(&line, ",\"job_id\":", json_string(job));
  }
  absl::StrAppend(&line, ",\"msg\":", json_string(message), "}\n");
  return line;
}

void JsonLogFormatter::format(const spdlog::details::log_msg& message, spdlog::memory_buf_t& out) {
  const std::string time =
      absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::FromChrono(message.time), absl::UTCTimeZone());
  const auto level = spdlog::level::to_string_view(message.level);
  const std::string line =
      json_log_line(time, std::string_view(level.data(), level.size()),
                    std::string_view(message.payload.data(), message.payload.size()));
  out.append(line.data(), line.data() + line.size());
}

std::unique_ptr<spdlog::formatter> JsonLogFormatter::clone() const {
  return std::make_unique<JsonLogFormatter>();
}

}  // namespace labelmesh::server
