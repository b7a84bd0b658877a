// SPDX-License-Identifier: AGPL-3.0-or-later
// The gRPC MeshingService: uploads become jobs, jobs are watched, cancelled,
// listed, and their results fetched. The work itself is the worker pool's.
#pragma once

#include <atomic>
#include <string>

#include "labelmesh/v1/service.grpc.pb.h"
#include "server/job_table.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/spool.h"
#include "server/stream_limits.h"

namespace labelmesh::server {

class MeshingService final : public v1::MeshingService::Service {
 public:
  // `token` empty: no authentication.
  MeshingService(JobTable& table, const Spool& spool, const ServerConfig& config, Metrics& metrics,
                 std::string token);

  // Refuses new uploads (UNAVAILABLE) from now on.
  void stop_accepting() { accepting_ = false; }

  grpc::Status Submit(grpc::ServerContext* context, grpc::ServerReader<v1::SubmitRequest>* reader,
                      v1::SubmitReply* reply) override;
  grpc::Status Watch(grpc::ServerContext* context, const v1::WatchRequest* request,
                     grpc::ServerWriter<v1::JobEvent>* writer) override;
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

 private:
  grpc::Status authenticate(const grpc::ServerContext& context);
  grpc::Status receive_upload(grpc::ServerReader<v1::SubmitRequest>& reader,
                              const v1::JobSpec& spec, const std::string& path,
                              StreamWatchdog::Ticket& ticket);
  // A place among the client's streams, or RESOURCE_EXHAUSTED (counted).
  absl::StatusOr<std::unique_ptr<StreamCounts::Slot>> open_stream(
      const grpc::ServerContext& context);
  // RESOURCE_EXHAUSTED "spool disk full" when an upload of this size would
  // leave less than the reserve free.
  absl::Status check_spool_space(uint64_t upload_bytes) const;

  JobTable& table_;
  const Spool& spool_;
  const ServerConfig& config_;
  Metrics& metrics_;
  const std::string token_;
  std::atomic<bool> accepting_{true};
  std::atomic<int> uploads_{0};
  StreamCounts streams_;
  StreamWatchdog watchdog_;
};

}  // namespace labelmesh::server
