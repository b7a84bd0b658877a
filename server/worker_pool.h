// SPDX-License-Identifier: AGPL-3.0-or-later
// Threads that take queued jobs and run each in a worker process.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/job_table.h"
#include "server/server_config.h"
#include "server/spool.h"

namespace labelmesh::server {

class WorkerPool {
 public:
  WorkerPool(JobTable& table, const Spool& spool, const ServerConfig& config);
  ~WorkerPool();

  void start();
  // Lets running jobs finish for up to `grace`, then stops the rest, which
  // stay queued on disk. The table must no longer dispatch.
  void drain(absl::Duration grace);
  // After the table is closed.
  void join();

 private:
  void run_thread();
  void run_job(const v1::JobRecord& record);

  JobTable& table_;
  const Spool& spool_;
  const ServerConfig& config_;
  std::string executable_;
  std::vector<std::thread> threads_;

  // No job running: what drain waits for.
  bool idle() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) { return busy_ == 0; }

  mutable absl::Mutex mutex_;
  int busy_ ABSL_GUARDED_BY(mutex_) = 0;
  std::atomic<bool> interrupt_{false};
};

}  // namespace labelmesh::server
