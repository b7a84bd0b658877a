// SPDX-License-Identifier: AGPL-3.0-or-later
// The gRPC MeshingService: uploads become jobs, jobs are watched, cancelled,
// listed, and their results fetched. The work itself is the workers'.
#pragma once

#include <atomic>
#include <mutex>
#include <string>

#include "labelmesh/v1/service.grpc.pb.h"
#include "server/audit_log.h"
#include "server/client_identity.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/stream_limits.h"
#include "server/submit_upload.h"

namespace labelmesh::server {

// Watch runs on gRPC's callback API (no thread per watcher); the other
// methods are synchronous.
class MeshingService final
    : public v1::MeshingService::WithCallbackMethod_Watch<v1::MeshingService::Service> {
 public:
  MeshingService(JobStore& store, const ServerConfig& config, Metrics& metrics,
                 ClientAuthenticator& authenticator, AuditLog& audit);

  // Refuses new uploads (UNAVAILABLE) from now on.
  void stop_accepting() { accepting_ = false; }

  grpc::Status Submit(grpc::ServerContext* context, grpc::ServerReader<v1::SubmitRequest>* reader,
                      v1::SubmitReply* reply) override;
  grpc::ServerWriteReactor<v1::JobEvent>* Watch(grpc::CallbackServerContext* context,
                                                const v1::WatchRequest* request) override;
  grpc::Status GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                      v1::Job* reply) override;
  grpc::Status ListJobs(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                        v1::ListJobsReply* reply) override;
  grpc::Status Cancel(grpc::ServerContext* context, const v1::CancelRequest* request,
                      v1::Job* reply) override;
  grpc::Status ListArtifacts(grpc::ServerContext* context, const v1::ListArtifactsRequest* request,
                             v1::ListArtifactsReply* reply) override;
  grpc::Status Fetch(grpc::ServerContext* context, const v1::FetchRequest* request,
                     grpc::ServerWriter<v1::FetchChunk>* writer) override;
  grpc::Status DeleteJob(grpc::ServerContext* context, const v1::DeleteJobRequest* request,
                         v1::DeleteJobReply* reply) override;

 private:
  // The caller's identity; a failure is counted and audited.
  absl::StatusOr<ClientIdentity> identify(const grpc::ServerContextBase& context, const char* call);
  // NOT_FOUND unless the id is well formed, the job exists and the caller
  // owns it or is an admin: other clients' jobs are not even named.
  absl::Status authorize(const ClientIdentity& identity, const std::string& job_id) const;
  // identify, then authorize for `job_id`.
  absl::StatusOr<ClientIdentity> authorized(const grpc::ServerContextBase& context,
                                            const char* call, const std::string& job_id);
  absl::Status fetch(grpc::ServerContext& context, const v1::FetchRequest& request,
                     grpc::ServerWriter<v1::FetchChunk>& writer);
  // A place among the client's streams, or RESOURCE_EXHAUSTED (counted).
  absl::StatusOr<std::unique_ptr<StreamCounts::Slot>> open_stream(
      const grpc::ServerContextBase& context, const ClientIdentity& identity);
  // The least an upload or a fetch must move, from the config.
  TransferRate transfer_rate() const;

  JobStore& store_;
  const ServerConfig& config_;
  Metrics& metrics_;
  ClientAuthenticator& authenticator_;
  AuditLog& audit_;
  RequestsInFlight requests_;
  // Held while a worker reads an upload the server cannot decode itself.
  std::timed_mutex volume_reader_;
  std::atomic<bool> accepting_{true};
  StreamCounts streams_;
  StreamCounts uploads_;
  StreamWatchdog watchdog_;
};

}  // namespace labelmesh::server
