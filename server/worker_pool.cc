// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/worker_pool.h"

#include <unistd.h>

#include "absl/strings/str_cat.h"
#include "server/job_limits.h"
#include "server/worker_process.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

WorkerPool::WorkerPool(JobTable& table, const Spool& spool, const ServerConfig& config)
    : table_(table), spool_(spool), config_(config) {
  executable_ = worker_executable(config);
}

WorkerPool::~WorkerPool() { join(); }

void WorkerPool::start() {
  for (int i = 0; i < config_.workers; ++i) threads_.emplace_back([this] { run_thread(); });
}

void WorkerPool::run_thread() {
  for (;;) {
    // A job taken on a full disk would fail, where it can wait in the queue.
    wait_for_output_room([this] { return spool_.free_bytes(); }, config_,
                         [this] { return table_.dispatching(); });
    auto record = table_.take_next();
    if (!record) break;
    {
      absl::MutexLock lock(&mutex_);
      ++busy_;
    }
    run_job(*record);
    absl::MutexLock lock(&mutex_);
    --busy_;
  }
}

void WorkerPool::run_job(const v1::JobRecord& record) {
  const std::string id = record.job().job_id();
  const uint32_t attempt = record.job().attempts();
  if (auto status = spool_.reset_output(id, attempt); !status.ok()) {
    table_.fail(id, static_cast<int>(status.code()), std::string(status.message()));
    return;
  }
  auto room = output_room(spool_.free_bytes(), config_);
  if (!room.ok() && is_disk_full(room.status())) {
    // The disk filled after wait_for_output_room: the job waits, it has not failed.
    table_.give_back(id);
    return;
  }
  if (!room.ok()) {
    table_.fail(id, static_cast<int>(room.status().code()), std::string(room.status().message()));
    return;
  }
  WorkerRun run;
  run.executable = executable_;
  run.job_dir = spool_.job_dir(id);
  run.output_dir = spool_.output_dir(id, attempt);
  run.log_path = spool_.worker_log(id);
  run.limits = worker_limits(config_, *room);
  run.deadline = absl::Now() + config_.job_timeout;
  run.on_event = [this, &id](v1::JobEvent event) { table_.publish(id, std::move(event)); };
  run.stop_request = [this, &id] {
    if (table_.cancel_requested(id)) return StopRequest::kCancel;
    if (interrupt_.load()) return StopRequest::kShutdown;
    return StopRequest::kNone;
  };
  WorkerOutcome outcome = run_worker_process(run);
  switch (outcome.kind) {
    case WorkerOutcome::Kind::kSucceeded: {
      auto artifacts = spool_.collect_artifacts(id, attempt);
      if (artifacts.ok()) artifacts = within_output_limit(std::move(*artifacts), config_);
      if (!artifacts.ok()) {
        // Results that cannot be delivered take no space.
        (void)spool_.reset_output(id, attempt);
        table_.fail(id, static_cast<int>(artifacts.status().code()),
                    std::string(artifacts.status().message()));
      } else {
        table_.succeed(id, outcome.report, std::move(*artifacts));
      }
      break;
    }
    case WorkerOutcome::Kind::kFailed:
      (void)spool_.reset_output(id, attempt);
      table_.fail(id, outcome.code, outcome.message);
      break;
    case WorkerOutcome::Kind::kCancelled:
      table_.mark_cancelled(id);
      break;
    case WorkerOutcome::Kind::kInterrupted:
      table_.requeue_interrupted(id);
      break;
  }
}

void WorkerPool::drain(absl::Duration grace) {
  absl::MutexLock lock(&mutex_);
  if (!mutex_.AwaitWithTimeout(absl::Condition(this, &WorkerPool::idle), grace)) {
    spdlog::warn("shutdown: {} jobs still running after the grace period; stopping them", busy_);
    interrupt_ = true;
    mutex_.Await(absl::Condition(this, &WorkerPool::idle));
  }
}

void WorkerPool::join() {
  for (auto& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
  threads_.clear();
}

}  // namespace labelmesh::server
