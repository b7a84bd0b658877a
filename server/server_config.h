// SPDX-License-Identifier: AGPL-3.0-or-later
// Everything labelmeshd can be told, with its defaults. Flags and LABELMESHD_*
// environment variables fill it (main.cc); tests build it directly.
#pragma once

#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace labelmesh::server {

struct ServerConfig {
  // all: one process with a local spool runs everything. frontend: serves
  // clients over the cluster's shared jobs. worker: runs the cluster's jobs.
  std::string role = "all";
  // The cluster's NATS server and the directory every frontend and worker
  // shares (uploads and results), for the frontend and worker roles.
  std::string nats_url;
  std::string artifact_dir;
  // How long a cluster worker may stay silent before its job goes to
  // another; the same on every machine (the first one to start sets it).
  absl::Duration cluster_ack_wait = absl::Seconds(30);

  std::string listen = "127.0.0.1:50051";
  // Prometheus metrics endpoint; empty for none.
  std::string metrics_listen;
  std::string spool_dir = "labelmeshd-spool";
  // 0 accepts and queues jobs without running them (a drained node).
  int workers = static_cast<int>(std::thread::hardware_concurrency());
  int queue_capacity = 64;
  absl::Duration job_timeout = absl::Minutes(30);
  absl::Duration result_ttl = absl::Hours(24);
  // Ended jobs kept at most; the oldest go first, before their TTL.
  int max_ended_jobs = 1000;
  // On SIGTERM: how long running jobs may take to finish before they are
  // stopped and left queued for the next start.
  absl::Duration shutdown_grace = absl::Seconds(30);

  uint64_t max_upload_bytes = uint64_t{2} << 30;
  // Free space the spool's disk keeps: an upload that would eat into it is
  // refused ("spool disk full") and health reports NOT_SERVING meanwhile, so
  // that running jobs can still write their results and records.
  uint64_t spool_reserve_bytes = uint64_t{512} << 20;
  // Most a job may write: no result file grows past it (nor past the free
  // space over the reserve when the job starts), and results larger in all
  // fail the job. Submit refuses an upload the spool could not hold together
  // with this much output. 0: no limit.
  uint64_t max_job_output_bytes = uint64_t{2} << 30;
  uint64_t max_voxels = uint64_t{1} << 31;
  // Uploads received at once: in all, per client and per client host. A
  // client is its identity; the identities every client may share
  // (anonymous, the --auth-token-file token) count per host instead.
  int max_concurrent_uploads = 8;
  int max_uploads_per_client = 4;
  int max_uploads_per_host = 6;
  // Streams (Submit, Watch, Fetch) one client, one client host and all
  // clients may hold open at once; clients count as for uploads.
  int max_streams_per_client = 16;
  int max_streams_per_host = 64;
  int max_streams = 256;
  // A stream that makes no progress this long is cancelled: an upload whose
  // next chunk does not come, a fetch or watch whose reader stopped reading.
  absl::Duration stream_idle_timeout = absl::Seconds(30);
  // Longest an upload or a fetch may take in all.
  absl::Duration transfer_deadline = absl::Minutes(30);
  // An upload or a fetch that moves fewer bytes per second than this over a
  // window, once its bytes have started, is cancelled: trickled bytes would
  // otherwise hold a slot until the transfer deadline. 0: no minimum.
  uint64_t min_transfer_rate = uint64_t{64} << 10;
  absl::Duration transfer_rate_window = absl::Seconds(30);
  // A cluster frontend deletes files in the shared upload folder that have
  // not changed for this long: a killed frontend's partial uploads. Living
  // uploads change at least every --stream-idle-timeout.
  absl::Duration abandoned_upload_age = absl::Minutes(5);
  // Largest gRPC message either way; upload and fetch chunks are 1 MiB.
  int max_message_bytes = 4 << 20;

  // Limits of each worker process: address space (0: none) and CPU seconds
  // (0: twice the job timeout).
  uint64_t worker_memory_bytes = uint64_t{8} << 30;
  uint64_t worker_cpu_seconds = 0;

  std::string tls_cert;
  std::string tls_key;
  // Requires clients to present a certificate signed by this CA (mutual TLS).
  std::string client_ca;
  // One line holding a bearer token shared by all clients (identity "token").
  std::string auth_token_file;
  // One client per line, `NAME TOKEN [admin]`: each client its own token.
  std::string clients_file;
  // Identities (token names or client certificate common names) that may see
  // and act on every client's jobs.
  std::vector<std::string> admin_identities;
  // Allow a non-loopback listen address without TLS.
  bool insecure = false;
  // Serve a non-loopback address (gRPC or metrics) without client
  // authentication.
  bool allow_anonymous = false;
  // A host that fails authentication this many times in a row is refused for
  // `auth_first_backoff`, doubling with each further failure.
  int auth_failures_before_backoff = 5;
  absl::Duration auth_first_backoff = absl::Seconds(1);
  absl::Duration auth_longest_backoff = absl::Minutes(5);
  // JSON lines, one per accepted, refused and deleted job; empty for
  // <spool>/audit.log.
  std::string audit_log;

  // The worker started as `<it> --worker JOB_DIR`; empty for labelmesh-worker
  // beside this process's own executable. Its --version must match ours.
  std::string worker_executable;

  bool tls() const { return !tls_cert.empty(); }
  bool clustered() const { return role != "all"; }
  // Clients prove who they are: tokens or client certificates.
  bool authenticates_clients() const {
    return !auth_token_file.empty() || !clients_file.empty() || !client_ca.empty();
  }
};

// INVALID_ARGUMENT naming the flag at fault: ranges, TLS files in pairs, a
// non-loopback address without TLS or --insecure, a non-loopback gRPC address
// without client authentication or --allow-anonymous, and a non-loopback
// metrics address without --allow-anonymous.
absl::Status validate_config(const ServerConfig& config);

// True for addresses whose host is 127.0.0.0/8, ::1 (also as
// ::ffff:127.x.y.z) or `localhost`, and for unix: sockets. Accepts
// host:port, [v6]:port and gRPC's ipv4:/ipv6: prefixes.
bool is_loopback_address(const std::string& address);

}  // namespace labelmesh::server
