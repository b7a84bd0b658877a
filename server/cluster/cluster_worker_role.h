// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd --role worker: `workers` job slots, each with its own cluster
// connection, pulling jobs from the shared queue and running each in a
// labelmesh-worker process under the same limits as on one machine. Inputs
// and results live in the shared directory, one out-<attempt> per attempt.
#pragma once

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "server/cluster/cluster_connection.h"
#include "server/cluster/cluster_worker.h"
#include "server/cluster/shared_artifacts.h"
#include "server/metrics.h"
#include "server/server_config.h"

namespace labelmesh::server {

class ClusterWorkerRole {
 public:
  // Connects every slot and starts pulling. Errors: those of connecting.
  // Counts jobs, their stages and how many run in `metrics`.
  static absl::StatusOr<std::unique_ptr<ClusterWorkerRole>> start(
      const ServerConfig& config, const cluster::ClusterSettings& settings,
      const cluster::SharedArtifacts& files, Metrics& metrics);
  ~ClusterWorkerRole();

  // False while a slot cannot reach NATS.
  bool healthy() const { return failing_slots_.load() == 0; }
  // Takes no more jobs; running ones get `grace` to finish, then are stopped
  // and given back to the queue for another worker. Joins the slots.
  void drain(absl::Duration grace);

 private:
  ClusterWorkerRole(const ServerConfig& config, const cluster::SharedArtifacts& files,
                    Metrics& metrics);
  void run_slot(cluster::ClusterConnection& connection);
  cluster::JobOutcome run_job(cluster::ClusterConnection& connection, const v1::JobRecord& record,
                              const cluster::Claim& claim, const std::atomic<bool>& cancelled);
  // Once the job's end is recorded: the other attempts' files go, and the
  // input unless kept; a job deleted while it ran goes whole. A refused end
  // takes its own attempt's files with it.
  void job_ended(cluster::ClusterConnection& connection, const cluster::Claim& claim,
                 const absl::StatusOr<v1::JobRecord>& ended);

  const ServerConfig& config_;
  const cluster::SharedArtifacts& files_;
  Metrics& metrics_;
  std::string executable_;
  cluster::ClusterWorkerConfig loop_;
  std::vector<std::unique_ptr<cluster::ClusterConnection>> connections_;
  std::vector<std::thread> slots_;

  std::atomic<bool> stopping_{false};
  std::atomic<bool> interrupt_{false};
  std::atomic<int> failing_slots_{0};
  // No job running: what drain waits for.
  bool idle() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) { return busy_ == 0; }

  mutable absl::Mutex mutex_;
  int busy_ ABSL_GUARDED_BY(mutex_) = 0;
};

}  // namespace labelmesh::server
