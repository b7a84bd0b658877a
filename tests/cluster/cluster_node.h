// SPDX-License-Identifier: AGPL-3.0-or-later
// One machine's view of a test cluster: its own connection to the test's
// nats-server, and its queue, job states, events and jobs on it.
#pragma once

#include <memory>
#include <string>

#include "absl/time/time.h"
#include "cluster/nats_server.h"
#include "server/cluster/cluster_connection.h"

namespace labelmesh::testing {

struct ClusterNode {
  // Every machine of a cluster has the same queue settings; tests pass a
  // short ack wait so a silent worker loses its job quickly.
  ClusterNode(const NatsServer& server, absl::Duration ack_wait) {
    cluster::ClusterSettings settings;
    settings.nats_url = server.url();
    settings.connection_name = "labelmesh-test";
    settings.queue.ack_wait = ack_wait;
    settings.connect_timeout = absl::Seconds(5);
    connection = std::move(cluster::ClusterConnection::open(settings).value());
    client = connection->client.get();
    queue = connection->queue.get();
    states = connection->states.get();
    events = connection->events.get();
    jobs = connection->jobs.get();
  }
  std::unique_ptr<cluster::ClusterConnection> connection;
  cluster::NatsClient* client = nullptr;
  cluster::JobQueue* queue = nullptr;
  cluster::JobStates* states = nullptr;
  cluster::EventLog* events = nullptr;
  cluster::ClusterJobs* jobs = nullptr;
};

// A job record with only its id set.
inline v1::JobRecord new_job(const std::string& id) {
  v1::JobRecord record;
  record.mutable_job()->set_job_id(id);
  return record;
}

}  // namespace labelmesh::testing
