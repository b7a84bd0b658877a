// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd assembled for its role. all: spool, job table, worker pool.
// frontend: the cluster's jobs behind the same gRPC service. worker: the
// cluster's job slots, with health only. Each with gRPC services (meshing,
// health, reflection), metrics and the expiry of old results.
#pragma once

#include <memory>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "server/server_config.h"

namespace grpc {
class Server;
}

namespace labelmesh::cluster {
struct ClusterConnection;
class SharedArtifacts;
}  // namespace labelmesh::cluster

namespace labelmesh::server {

class AuditLog;
class ClusterJobStore;
class ClusterWorkerRole;
class JobStore;
class ClientAuthenticator;
class JobTable;
class MeshingService;
class Metrics;
class Spool;
class WorkerPool;

// The grpc.health.v1 service name that answers SERVING for as long as the
// process serves: for liveness probes, which must not restart a process
// that is only unready.
inline constexpr char kLivenessService[] = "liveness";

class LabelmeshServer {
 public:
  // Validates the config, recovers the spool and starts serving.
  static absl::StatusOr<std::unique_ptr<LabelmeshServer>> start(ServerConfig config);
  ~LabelmeshServer();

  // The port bound (useful with a listen address ending in ":0").
  int port() const { return port_; }
  Metrics& metrics() { return *metrics_; }

  // Stops accepting uploads and starting jobs, lets running jobs finish for
  // the grace period (the rest stay queued on disk), then stops serving.
  void shutdown();

 private:
  LabelmeshServer() = default;
  // The local spool and its job table, for the role all.
  absl::Status open_spool();
  // The shared directory and the cluster, for the frontend and worker roles.
  absl::Status open_cluster();
  // Every few seconds: deletes expired jobs and updates health.
  void housekeeping_loop();
  // Health NOT_SERVING while a worker or frontend cannot reach the cluster,
  // or (role all) while the spool's disk is under its reserve; the
  // disk-pressure gauge.
  void update_health();

  ServerConfig config_;
  std::unique_ptr<ClientAuthenticator> authenticator_;
  std::unique_ptr<AuditLog> audit_;
  std::unique_ptr<Metrics> metrics_;
  std::unique_ptr<Spool> spool_;
  std::unique_ptr<JobTable> table_;
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<cluster::SharedArtifacts> files_;
  std::unique_ptr<cluster::ClusterConnection> cluster_;
  std::unique_ptr<ClusterJobStore> cluster_store_;
  std::unique_ptr<ClusterWorkerRole> cluster_workers_;
  // The table or the cluster store: what the service serves.
  JobStore* store_ = nullptr;
  std::unique_ptr<MeshingService> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;

  std::thread housekeeper_;
  bool under_reserve_ = false;
  absl::Mutex mutex_;
  bool stopped_ ABSL_GUARDED_BY(mutex_) = false;
};

}  // namespace labelmesh::server
