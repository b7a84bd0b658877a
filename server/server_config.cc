// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/server_config.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace labelmesh::server {

bool is_loopback_address(const std::string& address) {
  if (absl::StartsWith(address, "unix:")) return true;
  std::string host = address;
  if (absl::StartsWith(host, "ipv4:")) host = host.substr(5);
  if (absl::StartsWith(host, "ipv6:")) host = host.substr(5);
  if (absl::StartsWith(host, "[")) {
    return absl::StartsWith(host, "[::1]");
  }
  host = host.substr(0, host.rfind(':'));
  return host == "localhost" || absl::StartsWith(host, "127.");
}

absl::Status validate_config(const ServerConfig& c) {
  auto bad = [](const std::string& flag, const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat("--", flag, ": ", why));
  };
  if (c.workers < 0 || c.workers > 256) return bad("workers", "must be in [0, 256]");
  if (c.queue_capacity < 1) return bad("queue-capacity", "must be at least 1");
  if (c.job_timeout <= absl::ZeroDuration()) return bad("job-timeout", "must be positive");
  if (c.result_ttl <= absl::ZeroDuration()) return bad("result-ttl", "must be positive");
  if (c.max_ended_jobs < 1) return bad("max-ended-jobs", "must be at least 1");
  if (c.shutdown_grace < absl::ZeroDuration()) return bad("shutdown-grace", "must not be negative");
  if (c.max_upload_bytes < 1) return bad("max-upload-bytes", "must be positive");
  if (c.max_voxels < 1) return bad("max-voxels", "must be positive");
  if (c.max_concurrent_uploads < 1) return bad("max-concurrent-uploads", "must be at least 1");
  if (c.max_streams_per_client < 1) return bad("max-streams-per-client", "must be at least 1");
  if (c.max_streams < c.max_streams_per_client)
    return bad("max-streams", "must be at least --max-streams-per-client");
  if (c.stream_idle_timeout <= absl::ZeroDuration())
    return bad("stream-idle-timeout", "must be positive");
  if (c.transfer_deadline <= absl::ZeroDuration())
    return bad("transfer-deadline", "must be positive");
  if (c.max_message_bytes < (2 << 20)) {
    return bad("max-message-bytes", "must be at least 2 MiB (chunks are 1 MiB)");
  }
  if (c.tls_cert.empty() != c.tls_key.empty()) {
    return bad("tls-cert", "--tls-cert and --tls-key go together");
  }
  if (!c.client_ca.empty() && !c.tls()) return bad("client-ca", "needs --tls-cert and --tls-key");
  if (!c.tls() && !c.insecure && !is_loopback_address(c.listen)) {
    return bad("listen", "a non-loopback address needs TLS (--tls-cert, --tls-key) or --insecure");
  }
  return absl::OkStatus();
}

}  // namespace labelmesh::server
