// SPDX-License-Identifier: AGPL-3.0-or-later
// One Submit call, step by step: room for it on the server, the spec, the
// bytes, the volume's header, then the job. Each step that refuses returns a
// status marked with why (refusal.h); the service counts, audits and turns
// it into a gRPC status.
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "labelmesh/v1/service.grpc.pb.h"
#include "server/client_identity.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/server_config.h"
#include "server/stream_limits.h"

namespace labelmesh::server {

// The Submits in progress by (owner, request_id), so that a retry that races
// its first try waits instead of making a second job.
class RequestsInFlight {
 public:
  // Holds one (owner, request_id) until destroyed; an empty request_id
  // always gets one.
  class Claim {
   public:
    Claim(RequestsInFlight& requests, std::pair<std::string, std::string> key);
    ~Claim();
    Claim(const Claim&) = delete;
    Claim& operator=(const Claim&) = delete;
    bool claimed() const { return claimed_; }

   private:
    RequestsInFlight& requests_;
    std::pair<std::string, std::string> key_;
    bool claimed_ = false;
  };

 private:
  absl::Mutex mutex_;
  std::set<std::pair<std::string, std::string>> claims_ ABSL_GUARDED_BY(mutex_);
};

// What a Submit uses of the server, which outlives it.
struct SubmitServices {
  JobStore& store;
  const ServerConfig& config;
  Metrics& metrics;
  StreamWatchdog& watchdog;
  StreamCounts& streams;
  StreamCounts& uploads;
  RequestsInFlight& requests;
  // Held while a worker reads an upload the server cannot decode itself.
  std::timed_mutex& volume_reader;
  // The least an upload must move.
  TransferRate transfer_rate;
};

class SubmitUpload {
 public:
  SubmitUpload(SubmitServices services, grpc::ServerContext& context,
               grpc::ServerReader<v1::SubmitRequest>& reader, const ClientIdentity& identity)
      : services_(services), context_(context), reader_(reader), identity_(identity) {}

  // Fills `reply` with the new job, or with the job an earlier Submit of the
  // same request_id made (reply.existing). Otherwise a status marked with
  // why; the upload's file is gone then.
  absl::Status run(v1::SubmitReply& reply);

 private:
  // RESOURCE_EXHAUSTED "spool disk full" (marked) when an upload of this
  // size would leave less than the reserve free.
  absl::Status check_spool_space(uint64_t upload_bytes) const;
  // The chunks into `path`, checked against the spec's size and SHA-256.
  absl::Status receive(const v1::JobSpec& spec, const std::string& path,
                       StreamWatchdog::Ticket& ticket);

  SubmitServices services_;
  grpc::ServerContext& context_;
  grpc::ServerReader<v1::SubmitRequest>& reader_;
  const ClientIdentity& identity_;
};

}  // namespace labelmesh::server
