// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/worker_pool.h"

#include <algorithm>
#include <thread>

#include <unistd.h>

#include "absl/strings/str_cat.h"
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
  while (auto record = table_.take_next()) {
    {
      std::lock_guard lock(mutex_);
      ++busy_;
    }
    run_job(*record);
    std::lock_guard lock(mutex_);
    --busy_;
    idle_.notify_all();
  }
}

void WorkerPool::run_job(const v1::JobRecord& record) {
  const std::string id = record.job().job_id();
  const uint32_t attempt = record.job().attempts();
  if (auto status = spool_.reset_output(id, attempt); !status.ok()) {
    table_.fail(id, static_cast<int>(status.code()), std::string(status.message()));
    return;
  }
  WorkerRun run;
  run.executable = executable_;
  run.job_dir = spool_.job_dir(id);
  run.output_dir = spool_.output_dir(id, attempt);
  run.log_path = spool_.worker_log(id);
  run.limits.memory_bytes = config_.worker_memory_bytes;
  // Each worker meshes its labels on its share of the cores.
  run.limits.threads = std::max(1u, std::thread::hardware_concurrency() /
                                        static_cast<unsigned>(std::max(config_.workers, 1)));
  run.limits.cpu_seconds =
      config_.worker_cpu_seconds > 0
          ? config_.worker_cpu_seconds
          : static_cast<uint64_t>(2 * absl::ToDoubleSeconds(config_.job_timeout)) + 1;
  auto room = output_room();
  if (!room.ok()) {
    table_.fail(id, static_cast<int>(room.status().code()), std::string(room.status().message()));
    return;
  }
  run.limits.output_file_bytes = *room;
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
      if (artifacts.ok()) artifacts = within_output_limit(std::move(*artifacts));
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

absl::StatusOr<uint64_t> WorkerPool::output_room() const {
  auto free = spool_.free_bytes();
  if (!free.ok()) return free.status();
  const uint64_t over_reserve =
      *free > config_.spool_reserve_bytes ? *free - config_.spool_reserve_bytes : 0;
  if (over_reserve < kLeastOutputRoom) {
    return absl::ResourceExhaustedError(
        absl::StrCat("spool disk full: ", *free, " bytes free, no room over the reserve of ",
                     config_.spool_reserve_bytes, " bytes for the job's results"));
  }
  return config_.max_job_output_bytes > 0 ? std::min(config_.max_job_output_bytes, over_reserve)
                                          : over_reserve;
}

absl::StatusOr<std::vector<v1::Artifact>> WorkerPool::within_output_limit(
    std::vector<v1::Artifact> artifacts) const {
  uint64_t total = 0;
  for (const auto& artifact : artifacts) total += artifact.size_bytes();
  if (config_.max_job_output_bytes > 0 && total > config_.max_job_output_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the results came to ", total, " bytes, over the job's output limit of ",
                     config_.max_job_output_bytes, " bytes; ask for fewer labels or formats"));
  }
  return artifacts;
}

void WorkerPool::drain(absl::Duration grace) {
  std::unique_lock lock(mutex_);
  if (!idle_.wait_for(lock, absl::ToChronoMilliseconds(grace), [this] { return busy_ == 0; })) {
    spdlog::warn("shutdown: {} jobs still running after the grace period; stopping them", busy_);
    interrupt_ = true;
    idle_.wait(lock, [this] { return busy_ == 0; });
  }
}

void WorkerPool::join() {
  for (auto& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
  threads_.clear();
}

}  // namespace labelmesh::server
