// SPDX-License-Identifier: AGPL-3.0-or-later
// One machine's connection to the cluster: its NATS connection and, on it,
// the job queue, the job states, the event log and the job life built on
// them. Every frontend and worker opens one (a worker one per job slot, so
// that each slot pulls from the queue on its own).
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/cluster/cluster_jobs.h"

namespace labelmesh::cluster {

struct ClusterSettings {
  std::string nats_url;
  // Shown in the NATS server's monitoring: which machine and role.
  std::string connection_name = "labelmeshd";
  JobQueueConfig queue;
  EventLogConfig events;
  std::string states_bucket = "labelmesh_jobs";
  absl::Duration connect_timeout = absl::Seconds(10);
};

struct ClusterConnection {
  // Errors: UNAVAILABLE when NATS does not answer; those of the parts.
  static absl::StatusOr<std::unique_ptr<ClusterConnection>> open(const ClusterSettings& settings);

  std::unique_ptr<NatsClient> client;
  std::unique_ptr<JobQueue> queue;
  std::unique_ptr<JobStates> states;
  std::unique_ptr<EventLog> events;
  std::unique_ptr<ClusterJobs> jobs;
};

}  // namespace labelmesh::cluster
