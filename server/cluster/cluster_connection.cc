// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/cluster_connection.h"

#include "core/util/status_macros.h"

namespace labelmesh::cluster {

absl::StatusOr<std::unique_ptr<ClusterConnection>> ClusterConnection::open(
    const ClusterSettings& settings) {
  auto connection = std::make_unique<ClusterConnection>();
  auto client =
      NatsClient::connect(settings.nats_url, settings.connection_name, settings.connect_timeout);
  if (!client.ok()) return client.status();
  connection->client = std::move(*client);
  LABELMESH_ASSIGN_OR_RETURN(auto queue, JobQueue::open(*connection->client, settings.queue));
  connection->queue = std::move(queue);
  LABELMESH_ASSIGN_OR_RETURN(auto states,
                             JobStates::open(*connection->client, settings.states_bucket));
  connection->states = std::move(states);
  LABELMESH_ASSIGN_OR_RETURN(auto events, EventLog::open(*connection->client, settings.events));
  connection->events = std::move(events);
  connection->jobs =
      std::make_unique<ClusterJobs>(*connection->states, *connection->queue, *connection->events);
  return connection;
}

}  // namespace labelmesh::cluster
