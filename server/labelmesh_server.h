// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd assembled: spool, job table, worker pool, gRPC services
// (meshing, health, reflection), metrics and the expiry of old results.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "absl/status/statusor.h"
#include "server/server_config.h"

namespace grpc {
class Server;
}

namespace labelmesh::server {

class AuditLog;
class ClientAuthenticator;
class JobTable;
class MeshingService;
class Metrics;
class Spool;
class WorkerPool;

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
  // Every few seconds: deletes expired jobs and checks the spool's free
  // space against its reserve.
  void housekeeping_loop();
  // Health NOT_SERVING and the disk-pressure gauge while the spool's disk is
  // under its reserve.
  void check_spool_space();

  ServerConfig config_;
  std::unique_ptr<ClientAuthenticator> authenticator_;
  std::unique_ptr<AuditLog> audit_;
  std::unique_ptr<Metrics> metrics_;
  std::unique_ptr<Spool> spool_;
  std::unique_ptr<JobTable> table_;
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<MeshingService> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;

  std::thread housekeeper_;
  bool under_reserve_ = false;
  std::mutex mutex_;
  std::condition_variable stopping_;
  bool stopped_ = false;
};

}  // namespace labelmesh::server
