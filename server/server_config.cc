// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/server_config.h"

#include <algorithm>

#include <arpa/inet.h>
#include <netinet/in.h>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace labelmesh::server {

bool is_loopback_address(const std::string& address) {
  if (absl::StartsWith(address, "unix:")) return true;
  absl::string_view rest = address;
  if (!absl::ConsumePrefix(&rest, "ipv4:")) absl::ConsumePrefix(&rest, "ipv6:");
  std::string host;
  if (absl::ConsumePrefix(&rest, "[")) {
    const size_t close = rest.find(']');
    if (close == absl::string_view::npos) return false;
    host = std::string(rest.substr(0, close));
  } else {
    const size_t colon = rest.rfind(':');
    host = std::string(rest.substr(0, colon));
  }
  if (host == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, host.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  return false;
}

absl::Status validate_config(const ServerConfig& c) {
  auto bad = [](const std::string& flag, const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat("--", flag, ": ", why));
  };
  if (c.role != "all" && c.role != "frontend" && c.role != "worker")
    return bad("role", "must be all, frontend or worker");
  if (c.clustered() && c.nats_url.empty())
    return bad("nats-url", "the " + c.role + " role needs it");
  if (c.clustered() && c.artifact_dir.empty())
    return bad("artifact-dir", "the " + c.role + " role needs it");
  if (c.cluster_ack_wait < absl::Seconds(1)) return bad("cluster-ack-wait", "must be at least 1s");
  if (c.role == "worker" && c.workers < 1) return bad("workers", "a worker needs at least 1");
  if (c.workers < 0 || c.workers > 256) return bad("workers", "must be in [0, 256]");
  if (c.queue_capacity < 1) return bad("queue-capacity", "must be at least 1");
  if (c.job_timeout <= absl::ZeroDuration()) return bad("job-timeout", "must be positive");
  if (c.result_ttl <= absl::ZeroDuration()) return bad("result-ttl", "must be positive");
  if (c.max_ended_jobs < 1) return bad("max-ended-jobs", "must be at least 1");
  if (c.shutdown_grace < absl::ZeroDuration()) return bad("shutdown-grace", "must not be negative");
  if (c.max_upload_bytes < 1) return bad("max-upload-bytes", "must be positive");
  if (c.max_voxels < 1) return bad("max-voxels", "must be positive");
  if (c.max_concurrent_uploads < 1) return bad("max-concurrent-uploads", "must be at least 1");
  if (c.max_uploads_per_client < 1) return bad("max-uploads-per-client", "must be at least 1");
  if (c.max_uploads_per_host < c.max_uploads_per_client)
    return bad("max-uploads-per-host", "must be at least --max-uploads-per-client");
  if (c.max_streams_per_client < 1) return bad("max-streams-per-client", "must be at least 1");
  if (c.max_streams_per_host < c.max_streams_per_client)
    return bad("max-streams-per-host", "must be at least --max-streams-per-client");
  if (c.max_streams < c.max_streams_per_client)
    return bad("max-streams", "must be at least --max-streams-per-client");
  if (c.stream_idle_timeout <= absl::ZeroDuration())
    return bad("stream-idle-timeout", "must be positive");
  if (c.transfer_deadline <= absl::ZeroDuration())
    return bad("transfer-deadline", "must be positive");
  if (c.transfer_rate_window < absl::Seconds(1))
    return bad("transfer-rate-window", "must be at least 1s");
  // Only cluster frontends sweep the shared upload folder.
  if (c.role == "frontend" &&
      c.abandoned_upload_age < std::max(absl::Seconds(20), 2 * c.stream_idle_timeout))
    return bad("abandoned-upload-age", "must be at least 20s and twice --stream-idle-timeout");
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
  if (!c.authenticates_clients() && !c.allow_anonymous && !is_loopback_address(c.listen)) {
    return bad("listen",
               "a non-loopback address needs client authentication (--clients-file, "
               "--auth-token-file or --client-ca) or --allow-anonymous");
  }
  // /metrics is plain HTTP without authentication: tokens would cross the
  // network in the clear.
  if (!c.metrics_listen.empty() && !c.allow_anonymous && !is_loopback_address(c.metrics_listen)) {
    return bad("metrics-listen",
               "the metrics endpoint has no authentication: a non-loopback address needs "
               "--allow-anonymous");
  }
  if (c.auth_failures_before_backoff < 1)
    return bad("auth-failures-before-backoff", "must be at least 1");
  if (c.auth_first_backoff <= absl::ZeroDuration() || c.auth_longest_backoff < c.auth_first_backoff)
    return bad("auth-first-backoff", "must be positive and at most --auth-longest-backoff");
  return absl::OkStatus();
}

}  // namespace labelmesh::server
