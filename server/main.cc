// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd: the meshing service. Each job runs in a child process,
// labelmesh-worker, which alone links the core meshing library.
#include <signal.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string_view>
#include <thread>

#include "absl/time/time.h"
#include "server/json_log_format.h"
#include "server/labelmesh_server.h"
#include "server/worker_process.h"
#include "spdlog/sinks/stdout_color_sinks.h"
#include "spdlog/spdlog.h"

namespace {

using labelmesh::server::ServerConfig;

// A CLI11 option holding a duration such as 90s, 30m or 24h.
CLI::Option* add_duration(CLI::App& app, const std::string& name, absl::Duration& value,
                          const std::string& help) {
  auto* option = app.add_option_function<std::string>(
      name,
      [&value, name](const std::string& text) {
        if (!absl::ParseDuration(text, &value)) {
          throw CLI::ValidationError(name,
                                     "'" + text + "' is not a duration such as 90s, 30m, 24h");
        }
      },
      help + " (default " + absl::FormatDuration(value) + ")");
  return option;
}

void add_server_flags(CLI::App& app, ServerConfig& c) {
  auto env = [](CLI::Option* option, const char* variable) { option->envname(variable); };
  env(app.add_option("--role", c.role,
                     "all: one machine, local spool; frontend: serves clients over the cluster's "
                     "jobs; worker: runs the cluster's jobs")
          ->check(CLI::IsMember({"all", "frontend", "worker"}))
          ->capture_default_str(),
      "LABELMESHD_ROLE");
  env(app.add_option(
          "--nats-url", c.nats_url,
          "The cluster's NATS server with JetStream, nats://HOST:PORT (frontend, worker)"),
      "LABELMESHD_NATS_URL");
  env(app.add_option("--artifact-dir", c.artifact_dir,
                     "Directory every frontend and worker shares for uploads and results "
                     "(frontend, worker)"),
      "LABELMESHD_ARTIFACT_DIR");
  env(add_duration(app, "--cluster-ack-wait", c.cluster_ack_wait,
                   "A cluster worker silent this long loses its job to another; the same on "
                   "every machine"),
      "LABELMESHD_CLUSTER_ACK_WAIT");
  env(app.add_option("--listen", c.listen, "gRPC address")->capture_default_str(),
      "LABELMESHD_LISTEN");
  env(app.add_option("--metrics-listen", c.metrics_listen,
                     "Prometheus /metrics address, e.g. 127.0.0.1:9464 (default: none)"),
      "LABELMESHD_METRICS_LISTEN");
  env(app.add_option("--spool-dir", c.spool_dir, "Jobs, uploads and results")
          ->capture_default_str(),
      "LABELMESHD_SPOOL_DIR");
  env(app.add_option("--workers", c.workers, "Jobs run at once, each in a worker process")
          ->capture_default_str(),
      "LABELMESHD_WORKERS");
  env(app.add_option("--queue-capacity", c.queue_capacity, "Most jobs waiting to start")
          ->capture_default_str(),
      "LABELMESHD_QUEUE_CAPACITY");
  env(add_duration(app, "--job-timeout", c.job_timeout, "Longest a job may run"),
      "LABELMESHD_JOB_TIMEOUT");
  env(add_duration(app, "--result-ttl", c.result_ttl, "How long results stay fetchable"),
      "LABELMESHD_RESULT_TTL");
  env(app.add_option("--max-ended-jobs", c.max_ended_jobs,
                     "Ended jobs kept at most; the oldest are deleted first")
          ->capture_default_str(),
      "LABELMESHD_MAX_ENDED_JOBS");
  env(add_duration(app, "--shutdown-grace", c.shutdown_grace,
                   "On SIGTERM, how long running jobs may finish; the rest run at next start"),
      "LABELMESHD_SHUTDOWN_GRACE");
  env(app.add_option("--max-upload-bytes", c.max_upload_bytes, "Largest upload")
          ->capture_default_str(),
      "LABELMESHD_MAX_UPLOAD_BYTES");
  env(app.add_option("--max-streams-per-client", c.max_streams_per_client,
                     "Submit, Watch and Fetch streams one client may hold open (anonymous and "
                     "--auth-token-file clients: per host)")
          ->capture_default_str(),
      "LABELMESHD_MAX_STREAMS_PER_CLIENT");
  env(app.add_option("--max-streams-per-host", c.max_streams_per_host,
                     "Submit, Watch and Fetch streams all clients on one host may hold open")
          ->capture_default_str(),
      "LABELMESHD_MAX_STREAMS_PER_HOST");
  env(app.add_option("--max-streams", c.max_streams, "Streams all clients may hold open")
          ->capture_default_str(),
      "LABELMESHD_MAX_STREAMS");
  env(add_duration(app, "--stream-idle-timeout", c.stream_idle_timeout,
                   "A stream that makes no progress this long is cancelled"),
      "LABELMESHD_STREAM_IDLE_TIMEOUT");
  env(add_duration(app, "--transfer-deadline", c.transfer_deadline,
                   "Longest an upload or a fetch may take"),
      "LABELMESHD_TRANSFER_DEADLINE");
  env(app.add_option("--min-transfer-rate", c.min_transfer_rate,
                     "Bytes per second an upload or a fetch must move over each "
                     "--transfer-rate-window, or be cancelled (0: no minimum)")
          ->capture_default_str(),
      "LABELMESHD_MIN_TRANSFER_RATE");
  env(add_duration(app, "--transfer-rate-window", c.transfer_rate_window,
                   "The window --min-transfer-rate is measured over"),
      "LABELMESHD_TRANSFER_RATE_WINDOW");
  env(add_duration(app, "--abandoned-upload-age", c.abandoned_upload_age,
                   "A cluster frontend deletes shared uploads unchanged this long "
                   "(left by a killed frontend)"),
      "LABELMESHD_ABANDONED_UPLOAD_AGE");
  env(app.add_option("--spool-reserve-bytes", c.spool_reserve_bytes,
                     "Free spool disk space kept for running jobs; uploads into it are refused")
          ->capture_default_str(),
      "LABELMESHD_SPOOL_RESERVE_BYTES");
  env(app.add_option("--max-job-output-bytes", c.max_job_output_bytes,
                     "Most a job may write; an upload the spool cannot hold with this much output "
                     "is refused (0: no limit)")
          ->capture_default_str(),
      "LABELMESHD_MAX_JOB_OUTPUT_BYTES");
  env(app.add_option("--max-voxels", c.max_voxels, "Largest volume, voxels")->capture_default_str(),
      "LABELMESHD_MAX_VOXELS");
  env(app.add_option("--max-concurrent-uploads", c.max_concurrent_uploads,
                     "Uploads received at once")
          ->capture_default_str(),
      "LABELMESHD_MAX_CONCURRENT_UPLOADS");
  env(app.add_option("--max-uploads-per-client", c.max_uploads_per_client,
                     "Uploads received at once from one client (anonymous and --auth-token-file "
                     "clients: per host)")
          ->capture_default_str(),
      "LABELMESHD_MAX_UPLOADS_PER_CLIENT");
  env(app.add_option("--max-uploads-per-host", c.max_uploads_per_host,
                     "Uploads received at once from all clients on one host")
          ->capture_default_str(),
      "LABELMESHD_MAX_UPLOADS_PER_HOST");
  env(app.add_option("--max-message-bytes", c.max_message_bytes, "Largest gRPC message")
          ->capture_default_str(),
      "LABELMESHD_MAX_MESSAGE_BYTES");
  env(app.add_option("--worker-memory-bytes", c.worker_memory_bytes,
                     "Address-space limit of each worker process (0: none)")
          ->capture_default_str(),
      "LABELMESHD_WORKER_MEMORY_BYTES");
  env(app.add_option("--worker-cpu-seconds", c.worker_cpu_seconds,
                     "CPU-time limit of each worker process (0: twice --job-timeout)")
          ->capture_default_str(),
      "LABELMESHD_WORKER_CPU_SECONDS");
  env(app.add_option("--worker-executable", c.worker_executable,
                     "The worker program (default: labelmesh-worker beside labelmeshd)"),
      "LABELMESHD_WORKER_EXECUTABLE");
  env(app.add_option("--tls-cert", c.tls_cert, "PEM server certificate (chain)"),
      "LABELMESHD_TLS_CERT");
  env(app.add_option("--tls-key", c.tls_key, "PEM private key of --tls-cert"),
      "LABELMESHD_TLS_KEY");
  env(app.add_option("--client-ca", c.client_ca,
                     "PEM CA: require client certificates it signed (mutual TLS)"),
      "LABELMESHD_CLIENT_CA");
  env(app.add_option("--auth-token-file", c.auth_token_file,
                     "File holding one bearer token shared by all clients (identity 'token')"),
      "LABELMESHD_AUTH_TOKEN_FILE");
  env(app.add_option("--clients-file", c.clients_file,
                     "Client identities, one 'NAME TOKEN [admin]' per line; each client sees "
                     "only its own jobs, admins see all"),
      "LABELMESHD_CLIENTS_FILE");
  env(app.add_option("--admin-identity", c.admin_identities,
                     "An identity (token name or client certificate CN) that sees every job; "
                     "repeatable")
          ->delimiter(','),
      "LABELMESHD_ADMIN_IDENTITY");
  env(app.add_flag("--insecure", c.insecure,
                   "Allow a non-loopback --listen without TLS (trusted networks only)"),
      "LABELMESHD_INSECURE");
  env(app.add_flag("--allow-anonymous", c.allow_anonymous,
                   "Serve a non-loopback --listen or --metrics-listen without client "
                   "authentication (trusted networks only)"),
      "LABELMESHD_ALLOW_ANONYMOUS");
  env(app.add_option("--auth-failures-before-backoff", c.auth_failures_before_backoff,
                     "Failed authentications in a row after which a host is refused for a while")
          ->capture_default_str(),
      "LABELMESHD_AUTH_FAILURES_BEFORE_BACKOFF");
  env(app.add_option("--audit-log", c.audit_log,
                     "JSON lines, one per accepted, refused, deleted and expired job "
                     "(default: audit.log in the spool)"),
      "LABELMESHD_AUDIT_LOG");
}

// SIGTERM and SIGINT: blocked in every thread, then taken with sigwait by the
// main thread, never by a handler.
sigset_t stop_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  return signals;
}

}  // namespace

int main(int argc, char** argv) {
  // Blocked before any thread starts, so every thread inherits the mask.
  const sigset_t signals = stop_signals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);

  // Logs go to stderr, as a service manager or container runtime expects.
  spdlog::set_default_logger(spdlog::stderr_color_mt("labelmeshd"));
  ServerConfig config;
  std::string log_format = "auto";
  CLI::App app{"labelmeshd " LABELMESH_VERSION
               ": the labelmesh gRPC meshing service. Every flag can also be set with the "
               "environment variable named after it. Without TLS it listens on loopback only."};
  app.set_version_flag("--version", "labelmeshd " LABELMESH_VERSION);
  add_server_flags(app, config);
  app.add_option("--log-format", log_format,
                 "json (one object per line, UTC), text, or auto: text on a terminal, else json")
      ->check(CLI::IsMember({"auto", "json", "text"}))
      ->envname("LABELMESHD_LOG_FORMAT")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (log_format == "json" || (log_format == "auto" && isatty(STDERR_FILENO) != 1)) {
    spdlog::set_formatter(std::make_unique<labelmesh::server::JsonLogFormatter>());
  }

  auto server = labelmesh::server::LabelmeshServer::start(config);
  if (!server.ok()) {
    std::fprintf(stderr, "labelmeshd: %s\n", std::string(server.status().message()).c_str());
    return 2;
  }
  int number = 0;
  sigwait(&signals, &number);
  spdlog::info("received {}", number == SIGTERM ? "SIGTERM" : "SIGINT");
  (*server)->shutdown();
  return 0;
}
