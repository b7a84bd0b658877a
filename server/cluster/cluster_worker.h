// SPDX-License-Identifier: AGPL-3.0-or-later
// A worker's side of the shared queue: take a job, claim its next attempt,
// run it while telling the queue it is still at work, watch for a cancel,
// end it, and only then acknowledge it, so a worker that dies at any point
// leaves the job to the next one.
#pragma once

#include <atomic>
#include <functional>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/cluster/cluster_jobs.h"
#include "server/cluster/job_queue.h"

namespace labelmesh::cluster {

struct ClusterWorkerConfig {
  // How long to wait for a job; how often to say "still working" (well
  // under the queue's ack wait) and to look for a cancel.
  absl::Duration poll = absl::Seconds(1);
  absl::Duration heartbeat = absl::Seconds(5);
};

// How a run ended: SUCCEEDED, FAILED or CANCELLED, and what to record
// (report, artifacts or error); QUEUED for a run stopped by the worker's own
// shutdown, which gives the job back to the queue.
struct JobOutcome {
  v1::JobState state = v1::JOB_STATE_FAILED;
  v1::JobRecord result;
};

// Runs one attempt; `cancelled` turns true when a client cancels the job.
using RunJob = std::function<JobOutcome(const v1::JobRecord& record, const Claim& claim,
                                        const std::atomic<bool>& cancelled)>;
// Told how a run's end went, before the queue hears: the record as ended,
// or ABORTED when the job states refused it (another attempt holds the job).
using JobEnded =
    std::function<void(const Claim& claim, const absl::StatusOr<v1::JobRecord>& ended)>;

class ClusterWorker {
 public:
  ClusterWorker(JobQueue& queue, ClusterJobs& jobs, RunJob run, ClusterWorkerConfig config = {},
                JobEnded ended = nullptr)
      : queue_(queue),
        jobs_(jobs),
        run_(std::move(run)),
        config_(config),
        ended_(std::move(ended)) {}

  // Takes and handles one job if one comes within config.poll; true when
  // one came. A job that has ended or is gone is acknowledged without a
  // run; a result the job states refuse (another worker holds a newer
  // attempt) is dropped, unacknowledged; a job deleted while it ran is
  // acknowledged.
  absl::StatusOr<bool> run_one();

 private:
  JobQueue& queue_;
  ClusterJobs& jobs_;
  RunJob run_;
  ClusterWorkerConfig config_;
  JobEnded ended_;
};

}  // namespace labelmesh::cluster
