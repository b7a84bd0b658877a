// SPDX-License-Identifier: AGPL-3.0-or-later
// One machine's view of a test cluster: its own connection to the test's
// nats-server, and its queue, job states, events and jobs on it.
#pragma once

#include <memory>
#include <string>

#include "absl/time/time.h"
#include "cluster/nats_server.h"
#include "server/cluster/cluster_jobs.h"

namespace labelmesh::testing {

struct ClusterNode {
  // Every machine of a cluster has the same queue settings; tests pass a
  // short ack wait so a silent worker loses its job quickly.
  ClusterNode(const NatsServer& server, absl::Duration ack_wait) {
    client = std::move(
        cluster::NatsClient::connect(server.url(), "labelmesh-test", absl::Seconds(5)).value());
    cluster::JobQueueConfig config;
    config.ack_wait = ack_wait;
    queue = std::move(cluster::JobQueue::open(*client, config).value());
    states = std::move(cluster::JobStates::open(*client, "labelmesh_jobs").value());
    events = std::move(cluster::EventLog::open(*client, {}).value());
    jobs = std::make_unique<cluster::ClusterJobs>(*states, *queue, *events);
  }
  std::unique_ptr<cluster::NatsClient> client;
  std::unique_ptr<cluster::JobQueue> queue;
  std::unique_ptr<cluster::JobStates> states;
  std::unique_ptr<cluster::EventLog> events;
  std::unique_ptr<cluster::ClusterJobs> jobs;
};

// A job record with only its id set.
inline v1::JobRecord new_job(const std::string& id) {
  v1::JobRecord record;
  record.mutable_job()->set_job_id(id);
  return record;
}

}  // namespace labelmesh::testing
