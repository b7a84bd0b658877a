// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/cluster_worker_role.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "server/job_limits.h"
#include "server/spool.h"
#include "server/worker_process.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace fs = std::filesystem;
namespace {

cluster::JobOutcome failed(int code, const std::string& message) {
  cluster::JobOutcome outcome;
  outcome.state = v1::JOB_STATE_FAILED;
  outcome.result.mutable_job()->mutable_error()->set_code(code);
  outcome.result.mutable_job()->mutable_error()->set_message(message);
  return outcome;
}

cluster::JobOutcome failed(const absl::Status& status) {
  return failed(static_cast<int>(status.code()), std::string(status.message()));
}

// An empty directory at `dir`, whatever was there.
absl::Status fresh_directory(const std::string& dir) {
  std::error_code error;
  fs::remove_all(dir, error);
  fs::create_directories(dir, error);
  if (error) return spool_io_error(absl::StrCat("cannot create ", dir), error.value());
  return absl::OkStatus();
}

}  // namespace

ClusterWorkerRole::ClusterWorkerRole(const ServerConfig& config,
                                     const cluster::SharedArtifacts& files, Metrics& metrics)
    : config_(config), files_(files), metrics_(metrics), executable_(worker_executable(config)) {
  // Heartbeats well inside the ack wait, so that a live worker never loses
  // its job; cancels are seen within a heartbeat.
  loop_.heartbeat = std::min(absl::Seconds(5), config.cluster_ack_wait / 4);
  loop_.poll = absl::Seconds(1);
}

absl::StatusOr<std::unique_ptr<ClusterWorkerRole>> ClusterWorkerRole::start(
    const ServerConfig& config, const cluster::ClusterSettings& settings,
    const cluster::SharedArtifacts& files, Metrics& metrics) {
  std::unique_ptr<ClusterWorkerRole> role(new ClusterWorkerRole(config, files, metrics));
  for (int i = 0; i < config.workers; ++i) {
    LABELMESH_ASSIGN_OR_RETURN(auto connection, cluster::ClusterConnection::open(settings));
    role->connections_.push_back(std::move(connection));
  }
  for (auto& connection : role->connections_) {
    role->slots_.emplace_back([r = role.get(), c = connection.get()] { r->run_slot(*c); });
  }
  return role;
}

ClusterWorkerRole::~ClusterWorkerRole() { drain(absl::ZeroDuration()); }

void ClusterWorkerRole::run_slot(cluster::ClusterConnection& connection) {
  cluster::ClusterWorker worker(
      *connection.queue, *connection.jobs,
      [this, &connection](const v1::JobRecord& record, const cluster::Claim& claim,
                          const std::atomic<bool>& cancelled) {
        {
          absl::MutexLock lock(&mutex_);
          metrics_.set_running(++busy_);
        }
        cluster::JobOutcome outcome = run_job(connection, record, claim, cancelled);
        // A job given back at shutdown has not ended.
        static const char* const kOutcome[] = {"", "", "", "succeeded", "failed", "cancelled"};
        if (outcome.state != v1::JOB_STATE_QUEUED) metrics_.job_ended(kOutcome[outcome.state]);
        absl::MutexLock lock(&mutex_);
        metrics_.set_running(--busy_);
        return outcome;
      },
      loop_,
      [this, &connection](const cluster::Claim& claim, const absl::StatusOr<v1::JobRecord>& ended) {
        job_ended(connection, claim, ended);
      });
  bool failing = false;
  while (!stopping_.load()) {
    if (!wait_for_output_room([this] { return files_.free_bytes(); }, config_,
                              [this] { return !stopping_.load(); }))
      break;
    auto handled = worker.run_one();
    if (handled.ok() == failing) {
      // NATS away (or back): the slot says so once, and health follows.
      failing = !handled.ok();
      failing_slots_ += failing ? 1 : -1;
      if (failing) {
        spdlog::error("worker slot: {}", std::string(handled.status().message()));
      } else {
        spdlog::info("worker slot: the queue answers again");
      }
    }
    if (failing) std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  if (failing) --failing_slots_;
}

// The record itself is not read: the worker process reads the job's files.
cluster::JobOutcome ClusterWorkerRole::run_job(cluster::ClusterConnection& connection,
                                               const v1::JobRecord& /*record*/,
                                               const cluster::Claim& claim,
                                               const std::atomic<bool>& cancelled) {
  const std::string& id = claim.job_id;
  spdlog::info("job {} started (attempt {})", id, claim.attempt);
  const std::string out = files_.attempt_dir(id, claim.attempt);
  if (auto status = fresh_directory(out); !status.ok()) return failed(status);
  auto room = output_room(files_.free_bytes(), config_);
  if (!room.ok() && is_disk_full(room.status())) {
    // A cancel or delete that came meanwhile ends the job instead.
    if (auto now = connection.jobs->get(id);
        now.ok() && (now->cancel_requested() || now->deleted())) {
      cluster::JobOutcome result =
          failed(static_cast<int>(absl::StatusCode::kCancelled), "cancelled by a client");
      result.state = v1::JOB_STATE_CANCELLED;
      return result;
    }
    // The disk filled after wait_for_output_room: the job waits, it has not failed.
    spdlog::warn("job {}: {}; it goes back to the queue", id, std::string(room.status().message()));
    std::error_code ignored;
    fs::remove_all(out, ignored);
    cluster::JobOutcome given_back;
    given_back.state = v1::JOB_STATE_QUEUED;
    return given_back;
  }
  if (!room.ok()) return failed(room.status());
  const std::string job_dir = files_.job_dir(id);
  WorkerRun run;
  run.executable = executable_;
  run.job_dir = job_dir;
  run.output_dir = out;
  run.log_path = absl::StrCat(job_dir, "/worker-", claim.attempt, ".log");
  run.limits = worker_limits(config_, *room);
  run.deadline = absl::Now() + config_.job_timeout;
  run.on_event = [&](v1::JobEvent event) {
    if (event.has_stage_finished())
      metrics_.stage_finished(event.stage_finished().stage(), event.stage_finished().seconds());
    (void)connection.jobs->publish(claim, std::move(event));
  };
  run.stop_request = [&] {
    if (cancelled.load()) return StopRequest::kCancel;
    if (interrupt_.load()) return StopRequest::kShutdown;
    return StopRequest::kNone;
  };
  WorkerOutcome outcome = run_worker_process(run);
  cluster::JobOutcome result;
  switch (outcome.kind) {
    case WorkerOutcome::Kind::kSucceeded: {
      auto artifacts = list_artifacts(out);
      if (artifacts.ok()) artifacts = within_output_limit(std::move(*artifacts), config_);
      if (!artifacts.ok()) {
        (void)fresh_directory(out);  // results that cannot be delivered take no space
        return failed(artifacts.status());
      }
      result.state = v1::JOB_STATE_SUCCEEDED;
      *result.result.mutable_job()->mutable_report() = outcome.report;
      for (auto& artifact : *artifacts) *result.result.add_artifacts() = std::move(artifact);
      spdlog::info("job {} succeeded", id);
      return result;
    }
    case WorkerOutcome::Kind::kFailed:
      (void)fresh_directory(out);
      // The message may quote the volume's fields; the log keeps the code only.
      spdlog::warn("job {} failed with status code {}", id, outcome.code);
      return failed(outcome.code, outcome.message);
    case WorkerOutcome::Kind::kCancelled:
      result = failed(static_cast<int>(absl::StatusCode::kCancelled), "cancelled by a client");
      result.state = v1::JOB_STATE_CANCELLED;
      spdlog::info("job {} cancelled", id);
      return result;
    case WorkerOutcome::Kind::kInterrupted:
      break;
  }
  spdlog::info("job {} interrupted by shutdown; it goes back to the queue", id);
  result.state = v1::JOB_STATE_QUEUED;
  return result;
}

void ClusterWorkerRole::job_ended(cluster::ClusterConnection& connection,
                                  const cluster::Claim& claim,
                                  const absl::StatusOr<v1::JobRecord>& ended) {
  std::error_code error;
  if (!ended.ok()) {
    fs::remove_all(files_.attempt_dir(claim.job_id, claim.attempt), error);
    spdlog::info("job {} attempt {}: another attempt ended the job; this one's result dropped",
                 claim.job_id, claim.attempt);
    return;
  }
  const v1::JobRecord& record = *ended;
  const std::string& id = record.job().job_id();
  const std::string job_dir = files_.job_dir(id);
  if (record.deleted()) {
    files_.remove_job(id);
    (void)connection.jobs->erase(id);
    spdlog::info("job {} deleted by a client once it stopped", id);
    return;
  }
  (void)files_.remove_other_attempts(id, record.job().attempts());
  if (!record.spec().keep_input())
    fs::remove(absl::StrCat(job_dir, "/input", record.input_extension()), error);
}

void ClusterWorkerRole::drain(absl::Duration grace) {
  stopping_ = true;
  {
    absl::MutexLock lock(&mutex_);
    if (!mutex_.AwaitWithTimeout(absl::Condition(this, &ClusterWorkerRole::idle), grace)) {
      spdlog::warn("shutdown: {} jobs still running after the grace period; giving them back",
                   busy_);
    }
  }
  // Also for a job a slot took just as the grace ended.
  interrupt_ = true;
  for (auto& slot : slots_) {
    if (slot.joinable()) slot.join();
  }
  slots_.clear();
}

}  // namespace labelmesh::server
