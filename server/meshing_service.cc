// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/meshing_service.h"

#include <fstream>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/error_details.h"
#include "server/refusal.h"
#include "server/spool.h"
#include "server/submit_upload.h"
#include "server/watch_reactor.h"

namespace labelmesh::server {
namespace {

// An unknown or malformed id is NOT_FOUND; only well-formed ids reach paths.
absl::Status check_job_id(const std::string& job_id) {
  if (is_job_id(job_id)) return absl::OkStatus();
  return absl::NotFoundError("no such job (ids are 32 hex digits)");
}

// A Watch refused before it streams anything.
class RefusedWatch final : public grpc::ServerWriteReactor<v1::JobEvent> {
 public:
  explicit RefusedWatch(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace

MeshingService::MeshingService(JobStore& store, const ServerConfig& config, Metrics& metrics,
                               ClientAuthenticator& authenticator, AuditLog& audit)
    : store_(store),
      config_(config),
      metrics_(metrics),
      authenticator_(authenticator),
      audit_(audit),
      streams_({config.max_streams_per_client, config.max_streams_per_host, config.max_streams},
               "streams", Refusal::kTooManyStreams),
      uploads_({config.max_uploads_per_client, config.max_uploads_per_host,
                config.max_concurrent_uploads},
               "uploads", Refusal::kTooManyUploads) {}

absl::StatusOr<std::unique_ptr<StreamCounts::Slot>> MeshingService::open_stream(
    const grpc::ServerContextBase& context, const ClientIdentity& identity) {
  const ShareKeys keys = share_keys(identity, context.peer());
  auto slot = streams_.open(keys.client, keys.host);
  if (!slot.ok()) metrics_.rejected(Refusal::kTooManyStreams);
  return slot;
}

TransferRate MeshingService::transfer_rate() const {
  return {config_.min_transfer_rate, config_.transfer_rate_window};
}

absl::StatusOr<ClientIdentity> MeshingService::identify(const grpc::ServerContextBase& context,
                                                        const char* call) {
  auto identity = authenticator_.identify(context);
  if (identity.ok()) return identity;
  const bool backed_off = identity.status().code() == absl::StatusCode::kResourceExhausted;
  metrics_.rejected(backed_off ? Refusal::kAuthBackoff : Refusal::kUnauthenticated);
  // Calls refused by the backoff are counted, not logged one by one: they
  // come as fast as a client can send them, and would fill the disk.
  if (backed_off) return identity;
  audit_.record({.event = "unauthenticated",
                 .peer = peer_host(context.peer()),
                 .call = call,
                 .code = absl::StatusCodeToString(identity.status().code()),
                 .reason = "bad_credentials"});
  return identity;
}

absl::Status MeshingService::authorize(const ClientIdentity& identity,
                                       const std::string& job_id) const {
  LABELMESH_RETURN_IF_ERROR(check_job_id(job_id));
  auto owner = store_.owner(job_id);
  // The store unreachable is not "no such job".
  if (!owner.ok() && owner.status().code() != absl::StatusCode::kNotFound) return owner.status();
  if (!owner.ok() || (!identity.admin && *owner != identity.name))
    return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return absl::OkStatus();
}

absl::StatusOr<ClientIdentity> MeshingService::authorized(const grpc::ServerContextBase& context,
                                                          const char* call,
                                                          const std::string& job_id) {
  LABELMESH_ASSIGN_OR_RETURN(ClientIdentity identity, identify(context, call));
  LABELMESH_RETURN_IF_ERROR(authorize(identity, job_id));
  return identity;
}

grpc::Status MeshingService::Submit(grpc::ServerContext* context,
                                    grpc::ServerReader<v1::SubmitRequest>* reader,
                                    v1::SubmitReply* reply) {
  auto identity = identify(*context, "Submit");
  if (!identity.ok()) return to_grpc(identity.status());
  const SubmitServices services{store_,   config_,   metrics_,       watchdog_,      streams_,
                                uploads_, requests_, volume_reader_, transfer_rate()};
  const absl::Status status =
      accepting_
          ? SubmitUpload(services, *context, *reader, *identity).run(*reply)
          : refused(Refusal::kShuttingDown, absl::UnavailableError("the server is shutting down"));
  AuditEntry entry{.job_id = reply->job_id(),
                   .identity = identity->name,
                   .peer = peer_host(context->peer()),
                   .call = "Submit"};
  if (status.ok()) {
    entry.event = "accepted";
    if (reply->existing()) entry.reason = "repeated_request";
  } else {
    const Refusal why = refusal_of(status);
    metrics_.rejected(why);
    entry.event = "refused";
    entry.code = absl::StatusCodeToString(status.code());
    entry.reason = std::string(refusal_code(why));
  }
  audit_.record(entry);
  return to_grpc(status);
}

grpc::ServerWriteReactor<v1::JobEvent>* MeshingService::Watch(grpc::CallbackServerContext* context,
                                                              const v1::WatchRequest* request) {
  auto refuse = [](const absl::Status& status) { return new RefusedWatch(to_grpc(status)); };
  auto identity = authorized(*context, "Watch", request->job_id());
  if (!identity.ok()) return refuse(identity.status());
  auto stream = open_stream(*context, *identity);
  if (!stream.ok()) return refuse(stream.status());
  return WatchReactor::start(store_, watchdog_, config_.stream_idle_timeout, context,
                             request->job_id(), std::move(*stream));
}

grpc::Status MeshingService::GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                                    v1::Job* reply) {
  return to_grpc([&]() -> absl::Status {
    LABELMESH_RETURN_IF_ERROR(authorized(*context, "GetJob", request->job_id()));
    LABELMESH_ASSIGN_OR_RETURN(*reply, store_.get(request->job_id()));
    return absl::OkStatus();
  }());
}

grpc::Status MeshingService::ListJobs(grpc::ServerContext* context,
                                      const v1::ListJobsRequest* request,
                                      v1::ListJobsReply* reply) {
  return to_grpc([&]() -> absl::Status {
    LABELMESH_ASSIGN_OR_RETURN(const ClientIdentity identity, identify(*context, "ListJobs"));
    if (request->page_size() > 1000)
      return absl::InvalidArgumentError("page_size: must be at most 1000");
    JobStore::JobQuery query;
    if (!identity.admin) query.owner = identity.name;
    for (int state : request->states()) query.states.push_back(static_cast<v1::JobState>(state));
    query.page_size = request->page_size() == 0 ? 100 : request->page_size();
    query.page_token = request->page_token();
    LABELMESH_ASSIGN_OR_RETURN(auto page, store_.list(query));
    for (auto& job : page.jobs) *reply->add_jobs() = std::move(job);
    reply->set_next_page_token(page.next_page_token);
    return absl::OkStatus();
  }());
}

grpc::Status MeshingService::Cancel(grpc::ServerContext* context, const v1::CancelRequest* request,
                                    v1::Job* reply) {
  return to_grpc([&]() -> absl::Status {
    LABELMESH_RETURN_IF_ERROR(authorized(*context, "Cancel", request->job_id()));
    LABELMESH_ASSIGN_OR_RETURN(*reply, store_.cancel(request->job_id()));
    return absl::OkStatus();
  }());
}

grpc::Status MeshingService::ListArtifacts(grpc::ServerContext* context,
                                           const v1::ListArtifactsRequest* request,
                                           v1::ListArtifactsReply* reply) {
  return to_grpc([&]() -> absl::Status {
    LABELMESH_RETURN_IF_ERROR(authorized(*context, "ListArtifacts", request->job_id()));
    LABELMESH_ASSIGN_OR_RETURN(auto artifacts, store_.artifacts(request->job_id()));
    for (auto& artifact : artifacts) *reply->add_artifacts() = std::move(artifact);
    return absl::OkStatus();
  }());
}

grpc::Status MeshingService::Fetch(grpc::ServerContext* context, const v1::FetchRequest* request,
                                   grpc::ServerWriter<v1::FetchChunk>* writer) {
  return to_grpc(fetch(*context, *request, *writer));
}

absl::Status MeshingService::fetch(grpc::ServerContext& context, const v1::FetchRequest& request,
                                   grpc::ServerWriter<v1::FetchChunk>& writer) {
  LABELMESH_ASSIGN_OR_RETURN(const ClientIdentity identity,
                             authorized(context, "Fetch", request.job_id()));
  LABELMESH_ASSIGN_OR_RETURN(const auto artifacts, store_.artifacts(request.job_id()));
  // Only names the job recorded are served: nothing else in the spool is reachable.
  const v1::Artifact* artifact = nullptr;
  for (const auto& candidate : artifacts) {
    if (candidate.name() == request.artifact()) artifact = &candidate;
  }
  if (artifact == nullptr)
    return absl::NotFoundError(absl::StrCat("job has no artifact '", request.artifact(), "'"));
  LABELMESH_ASSIGN_OR_RETURN(const v1::Job job, store_.get(request.job_id()));
  std::ifstream in(store_.artifact_path(job, artifact->name()), std::ios::binary);
  if (!in) return absl::NotFoundError("the artifact expired or was removed");
  LABELMESH_ASSIGN_OR_RETURN(const auto stream, open_stream(context, identity));
  auto ticket = watchdog_.watch(&context, config_.stream_idle_timeout, config_.transfer_deadline,
                                "fetch", transfer_rate());
  v1::FetchChunk chunk;
  *chunk.mutable_artifact() = *artifact;
  std::string buffer(kChunkBytes, '\0');
  uint64_t sent = 0;
  do {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    chunk.set_data(buffer.data(), static_cast<size_t>(in.gcount()));
    if (!writer.Write(chunk)) return ticket->cancellation_or(absl::CancelledError("reader left"));
    sent += chunk.data().size();
    ticket->touch(sent);
    chunk.clear_artifact();
  } while (in);
  return absl::OkStatus();
}

grpc::Status MeshingService::DeleteJob(grpc::ServerContext* context,
                                       const v1::DeleteJobRequest* request,
                                       v1::DeleteJobReply* reply) {
  return to_grpc([&]() -> absl::Status {
    LABELMESH_ASSIGN_OR_RETURN(const ClientIdentity identity,
                               authorized(*context, "DeleteJob", request->job_id()));
    LABELMESH_ASSIGN_OR_RETURN(const v1::JobState state, store_.remove(request->job_id()));
    audit_.record({.event = "deleted",
                   .job_id = request->job_id(),
                   .identity = identity.name,
                   .peer = peer_host(context->peer()),
                   .call = "DeleteJob"});
    reply->set_state(state);
    return absl::OkStatus();
  }());
}

}  // namespace labelmesh::server
