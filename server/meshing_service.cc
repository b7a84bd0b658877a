// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/meshing_service.h"

#include <filesystem>
#include <fstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/digest/sha256.h"
#include "core/pipeline/job_options.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "server/error_details.h"
#include "server/spool.h"
#include "server/upload_checks.h"
#include "server/watch_reactor.h"
#include "server/worker_process.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace {

constexpr size_t kChunkBytes = 1 << 20;
// Longest a worker may take to read an upload the server cannot decode.
constexpr std::chrono::milliseconds kVolumeCheckTime{120'000};
// How often a living upload's modification time is renewed while nothing is
// written to it; half the shortest --abandoned-upload-age.
constexpr std::chrono::seconds kUploadMarkInterval{10};

grpc::Status invalid(const std::string& message) {
  return to_grpc(absl::InvalidArgumentError(message));
}

// An unknown or malformed id is NOT_FOUND; only well-formed ids reach paths.
grpc::Status check_job_id(const std::string& job_id) {
  if (is_job_id(job_id)) return grpc::Status::OK;
  return grpc::Status(grpc::StatusCode::NOT_FOUND, "no such job (ids are 32 hex digits)");
}

// The status of a stream the watchdog cancelled, else `otherwise`.
grpc::Status stalled_or(const StreamWatchdog::Ticket& ticket, grpc::Status otherwise) {
  const std::string reason = ticket.cancelled_because();
  if (reason.empty()) return otherwise;
  return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, reason);
}

// A Watch refused before it streams anything.
class RefusedWatch final : public grpc::ServerWriteReactor<v1::JobEvent> {
 public:
  explicit RefusedWatch(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

// Holds a (owner, request_id) among the submits in progress.
class RequestClaim {
 public:
  RequestClaim(std::mutex& mutex, std::set<std::pair<std::string, std::string>>& claims,
               std::pair<std::string, std::string> key)
      : mutex_(mutex), claims_(claims), key_(std::move(key)) {
    std::lock_guard lock(mutex_);
    claimed_ = key_.second.empty() || claims_.insert(key_).second;
  }
  ~RequestClaim() {
    if (!claimed_ || key_.second.empty()) return;
    std::lock_guard lock(mutex_);
    claims_.erase(key_);
  }
  bool claimed() const { return claimed_; }

 private:
  std::mutex& mutex_;
  std::set<std::pair<std::string, std::string>>& claims_;
  std::pair<std::string, std::string> key_;
  bool claimed_ = false;
};

// Deletes the upload file unless it was handed to a job. While the upload
// lives its modification time stays recent, also through checks that write
// nothing, so that frontends sweeping a shared upload folder can tell it
// from one a killed frontend left behind.
class UploadFile {
 public:
  explicit UploadFile(std::string path) : path_(std::move(path)) {}
  ~UploadFile() {
    std::error_code ignored;
    if (!kept_) std::filesystem::remove(path_, ignored);
  }
  const std::string& path() const { return path_; }
  void keep() { kept_ = true; }
  void mark_alive() {
    const auto now = std::filesystem::file_time_type::clock::now();
    if (now - marked_ < kUploadMarkInterval) return;
    std::error_code ignored;
    std::filesystem::last_write_time(path_, now, ignored);
    marked_ = now;
  }

 private:
  std::string path_;
  bool kept_ = false;
  std::filesystem::file_time_type marked_ = std::filesystem::file_time_type::clock::now();
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
               "streams"),
      uploads_({config.max_uploads_per_client, config.max_uploads_per_host,
                config.max_concurrent_uploads},
               "uploads") {}

absl::StatusOr<std::unique_ptr<StreamCounts::Slot>> MeshingService::open_stream(
    const grpc::ServerContextBase& context, const ClientIdentity& identity) {
  const ShareKeys keys = share_keys(identity, context.peer());
  auto slot = streams_.open(keys.client, keys.host);
  if (!slot.ok()) metrics_.rejected("too_many_streams");
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
  metrics_.rejected(backed_off ? "auth_backoff" : "unauthenticated");
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

grpc::Status MeshingService::authorize(const ClientIdentity& identity,
                                       const std::string& job_id) const {
  LABELMESH_RETURN_IF_ERROR(check_job_id(job_id));
  auto owner = store_.owner(job_id);
  // The store unreachable is not "no such job".
  if (!owner.ok() && owner.status().code() != absl::StatusCode::kNotFound)
    return to_grpc(owner.status());
  if (!owner.ok() || (!identity.admin && *owner != identity.name)) {
    return grpc::Status(grpc::StatusCode::NOT_FOUND, absl::StrCat("no job ", job_id));
  }
  return grpc::Status::OK;
}

absl::Status MeshingService::check_spool_space(uint64_t upload_bytes) const {
  auto free = store_.free_bytes();
  if (!free.ok()) return free.status();
  // The job's results must fit too; what they will come to is not known
  // before the job runs, so its output limit stands for them.
  const uint64_t outputs = config_.max_job_output_bytes;
  // Saturating: a huge limit must not wrap around to a small sum.
  const uint64_t needed = config_.spool_reserve_bytes + upload_bytes;
  const bool fits =
      needed >= config_.spool_reserve_bytes && *free >= needed && *free - needed >= outputs;
  if (!fits) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "spool disk full: ", *free, " bytes free, an upload of ", upload_bytes,
        " bytes and results of up to ", outputs, " bytes would leave less than the reserve of ",
        config_.spool_reserve_bytes, "; try again later"));
  }
  return absl::OkStatus();
}

grpc::Status MeshingService::receive_upload(grpc::ServerReader<v1::SubmitRequest>& reader,
                                            const v1::JobSpec& spec, const std::string& path,
                                            StreamWatchdog::Ticket& ticket, std::string& reason) {
  // Each refusal is counted here, by its reason, and only here.
  auto refuse = [&](const char* why, const std::string& message) {
    reason = why;
    return invalid(message);
  };
  auto spool_failed = [&](const absl::Status& status) {
    reason = status.code() == absl::StatusCode::kResourceExhausted ? "disk_full" : "spool_error";
    return to_grpc(status);
  };
  FileWriter out;
  if (auto status = out.open(path); !status.ok()) return spool_failed(status);
  digest::Sha256 hash;
  uint64_t received = 0;
  v1::SubmitRequest message;
  while (reader.Read(&message)) {
    ticket.touch(received + message.chunk().size());
    if (!message.has_chunk()) {
      return refuse("bad_request", "after the spec, every message must be a chunk");
    }
    const std::string& chunk = message.chunk();
    if (chunk.size() > kChunkBytes) return refuse("bad_request", "chunk: over 1 MiB");
    if (received + chunk.size() > spec.size_bytes()) {
      return refuse("bad_request", absl::StrCat("upload: more bytes than spec.size_bytes (",
                                                spec.size_bytes(), ")"));
    }
    if (auto status = out.append(chunk); !status.ok()) return spool_failed(status);
    hash.update(chunk);
    received += chunk.size();
  }
  if (const std::string stalled = ticket.cancelled_because(); !stalled.empty()) {
    reason = absl::StrContains(stalled, "too slow") ? "too_slow" : "stalled";
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, stalled);
  }
  // The checks that follow are progress too, but move no bytes.
  ticket.end_transfer();
  if (auto status = out.finish(); !status.ok()) return spool_failed(status);
  if (received < spec.size_bytes()) {
    return refuse("bad_request", absl::StrCat("upload: truncated, ", received, " of ",
                                              spec.size_bytes(), " bytes received"));
  }
  if (hash.hex_digest() != spec.sha256()) {
    return refuse("bad_digest", "upload: SHA-256 of the bytes received does not match spec.sha256");
  }
  return grpc::Status::OK;
}

grpc::Status MeshingService::Submit(grpc::ServerContext* context,
                                    grpc::ServerReader<v1::SubmitRequest>* reader,
                                    v1::SubmitReply* reply) {
  auto identity = identify(*context, "Submit");
  if (!identity.ok()) return to_grpc(identity.status());
  std::string reason;
  const grpc::Status status = submit(*context, *reader, *identity, *reply, reason);
  AuditEntry entry{.job_id = reply->job_id(),
                   .identity = identity->name,
                   .peer = peer_host(context->peer()),
                   .call = "Submit"};
  if (status.ok()) {
    entry.event = "accepted";
    if (reply->existing()) entry.reason = "repeated_request";
  } else {
    if (reason.empty()) reason = "refused";
    metrics_.rejected(reason);
    entry.event = "refused";
    entry.code = absl::StatusCodeToString(static_cast<absl::StatusCode>(status.error_code()));
    entry.reason = reason;
  }
  audit_.record(entry);
  return status;
}

grpc::Status MeshingService::submit(grpc::ServerContext& context,
                                    grpc::ServerReader<v1::SubmitRequest>& reader,
                                    const ClientIdentity& identity, v1::SubmitReply& reply,
                                    std::string& reason) {
  if (!accepting_) {
    reason = "shutting_down";
    return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
  }
  // Refused before the upload, not after it has all been received.
  if (auto status = store_.available(); !status.ok()) {
    reason = "store_unavailable";
    return to_grpc(status);
  }
  const ShareKeys keys = share_keys(identity, context.peer());
  auto stream = streams_.open(keys.client, keys.host);
  if (!stream.ok()) {
    reason = "too_many_streams";
    return to_grpc(stream.status());
  }
  // The spec is the first step: a client that sends nothing is dropped too.
  auto ticket = watchdog_.watch(&context, config_.stream_idle_timeout, config_.transfer_deadline,
                                "upload", transfer_rate());
  // Shares of the upload slots: one client, or one host, cannot take them all.
  auto upload_slot = uploads_.open(keys.client, keys.host);
  if (!upload_slot.ok()) {
    reason = "too_many_uploads";
    return to_grpc(upload_slot.status());
  }
  v1::SubmitRequest first;
  if (!reader.Read(&first) || !first.has_spec()) {
    reason = ticket->cancelled_because().empty() ? "bad_request" : "stalled";
    return stalled_or(*ticket, invalid("the first message must hold the job spec"));
  }
  ticket->touch();
  v1::JobSpec spec = first.spec();
  if (auto status = check_spec(spec, config_); !status.ok()) {
    reason = absl::StartsWith(status.message(), "spec.size_bytes") ? "too_large" : "bad_request";
    return to_grpc(status);
  }
  // A retried Submit gets the job its first try made.
  RequestClaim claim(requests_mutex_, requests_in_flight_, {identity.name, spec.request_id()});
  if (!claim.claimed()) {
    reason = "request_in_progress";
    return grpc::Status(grpc::StatusCode::ABORTED,
                        "a Submit with this request_id is still in progress; retry later");
  }
  if (!spec.request_id().empty()) {
    if (auto prior = store_.find_request(identity.name, spec.request_id())) {
      if (prior->sha256 != spec.sha256()) {
        reason = "request_id_reused";
        return grpc::Status(grpc::StatusCode::ALREADY_EXISTS,
                            "spec.request_id: already used for an upload with another sha256");
      }
      reply.set_job_id(prior->job_id);
      reply.set_queue_position(prior->queue_position);
      reply.set_existing(true);
      return grpc::Status::OK;
    }
  }
  if (store_.queue_full()) {
    reason = "queue_full";
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "the job queue is full; try again later");
  }
  if (auto status = check_spool_space(spec.size_bytes()); !status.ok()) {
    reason = "disk_full";
    return to_grpc(status);
  }
  // The job's voxel limit is the smaller of the client's and the server's.
  auto& options = *spec.mutable_options();
  const uint64_t voxel_limit = options.max_voxels() == 0
                                   ? config_.max_voxels
                                   : std::min<uint64_t>(options.max_voxels(), config_.max_voxels);
  options.set_max_voxels(voxel_limit);
  // The job keeps its options as the pipeline reads them, defaults filled in,
  // so that GetJob shows what the job runs with. check_spec parsed them.
  const MeshParams params = *params_from_options(options);
  options = make_options(params);

  const std::string job_id = store_.new_job_id_for(identity.name, spec.request_id());
  const std::string extension = *upload_extension(spec.file_name());
  // DICOM surfaces take their patient and study from a DICOM SEG: refused
  // before the upload rather than by the worker.
  if (params.dicom_surfaces && extension != ".dcm") {
    reason = "bad_request";
    return invalid(
        absl::StrCat("spec.options.formats: dcm needs a DICOM SEG upload (.dcm), not ", extension));
  }
  UploadFile upload(store_.upload_path(job_id, extension));
  LABELMESH_RETURN_IF_ERROR(receive_upload(reader, spec, upload.path(), *ticket, reason));
  upload.mark_alive();
  auto geometry = check_uploaded_volume(upload.path(), voxel_limit, config_.worker_memory_bytes);
  if (!geometry.ok()) {
    reason = "bad_volume";
    return to_grpc(geometry.status());
  }
  // VTK XML arrays (base64, appended, compressed blocks) are decoded only by
  // VTK's reader, and DICOM SEG pixel data and segments only by DCMTK's,
  // neither of which the server links: a worker reads them. Progress for
  // the watchdog is the reader's, and a client that leaves stops it; one
  // reader at a time, so that uploads cannot multiply the worker memory limit
  // outside the pool.
  if (extension == ".vti" || extension == ".dcm") {
    auto keep_going = [&] {
      ticket->touch();
      upload.mark_alive();
      return !context.IsCancelled();
    };
    std::unique_lock reading(volume_reader_, std::defer_lock);
    while (!reading.try_lock_for(std::chrono::milliseconds(500))) {
      if (!keep_going()) {
        reason = "stalled";
        return grpc::Status(grpc::StatusCode::CANCELLED, "the client left");
      }
    }
    auto read = check_volume_in_worker(worker_executable(config_), upload.path(), voxel_limit,
                                       params.limits.separate_overlapping,
                                       config_.worker_memory_bytes, kVolumeCheckTime, keep_going);
    if (!read.ok()) {
      reason = "bad_volume";
      return to_grpc(read);
    }
  }
  if (auto status = check_sizing_for_grid(params.poisson, *geometry); !status.ok()) {
    reason = "bad_request";
    return invalid(absl::StrCat("spec.options: ", status.message()));
  }

  v1::JobRecord record;
  v1::Job& job = *record.mutable_job();
  job.set_job_id(job_id);
  job.set_created_at(unix_now());
  job.set_owner(identity.name);
  *job.mutable_options() = spec.options();
  // Only the extension of the client's file name is kept: names can hold
  // patient identifiers.
  spec.set_file_name(absl::StrCat("upload", extension));
  *record.mutable_spec() = spec;
  record.set_input_extension(extension);
  // A client that left (or the watchdog dropped) hears nothing: no job.
  if (context.IsCancelled()) {
    reason = "stalled";
    return stalled_or(*ticket, grpc::Status(grpc::StatusCode::CANCELLED, "the client left"));
  }
  auto position = store_.accept(std::move(record), upload.path());
  if (!position.ok()) {
    if (position.status().code() == absl::StatusCode::kResourceExhausted) {
      reason = absl::StartsWith(position.status().message(), "spool disk full") ? "disk_full"
                                                                                : "queue_full";
    }
    return to_grpc(position.status());
  }
  upload.keep();
  reply.set_job_id(job_id);
  reply.set_queue_position(*position);
  metrics_.upload_bytes(spec.size_bytes());
  return grpc::Status::OK;
}

grpc::ServerWriteReactor<v1::JobEvent>* MeshingService::Watch(grpc::CallbackServerContext* context,
                                                              const v1::WatchRequest* request) {
  auto refuse = [](const grpc::Status& status) { return new RefusedWatch(status); };
  auto identity = identify(*context, "Watch");
  if (!identity.ok()) return refuse(to_grpc(identity.status()));
  if (auto status = authorize(*identity, request->job_id()); !status.ok()) return refuse(status);
  auto stream = open_stream(*context, *identity);
  if (!stream.ok()) return refuse(to_grpc(stream.status()));
  return WatchReactor::start(store_, watchdog_, config_.stream_idle_timeout, context,
                             request->job_id(), std::move(*stream));
}

grpc::Status MeshingService::GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                                    v1::Job* reply) {
  auto identity = identify(*context, "GetJob");
  if (!identity.ok()) return to_grpc(identity.status());
  LABELMESH_RETURN_IF_ERROR(authorize(*identity, request->job_id()));
  auto job = store_.get(request->job_id());
  if (!job.ok()) return to_grpc(job.status());
  *reply = std::move(*job);
  return grpc::Status::OK;
}

grpc::Status MeshingService::ListJobs(grpc::ServerContext* context,
                                      const v1::ListJobsRequest* request,
                                      v1::ListJobsReply* reply) {
  auto identity = identify(*context, "ListJobs");
  if (!identity.ok()) return to_grpc(identity.status());
  if (request->page_size() > 1000) return invalid("page_size: must be at most 1000");
  JobStore::JobQuery query;
  if (!identity->admin) query.owner = identity->name;
  for (int state : request->states()) query.states.push_back(static_cast<v1::JobState>(state));
  query.page_size = request->page_size() == 0 ? 100 : request->page_size();
  query.page_token = request->page_token();
  auto page = store_.list(query);
  if (!page.ok()) return to_grpc(page.status());
  for (auto& job : page->jobs) *reply->add_jobs() = std::move(job);
  reply->set_next_page_token(page->next_page_token);
  return grpc::Status::OK;
}

grpc::Status MeshingService::Cancel(grpc::ServerContext* context, const v1::CancelRequest* request,
                                    v1::Job* reply) {
  auto identity = identify(*context, "Cancel");
  if (!identity.ok()) return to_grpc(identity.status());
  LABELMESH_RETURN_IF_ERROR(authorize(*identity, request->job_id()));
  auto job = store_.cancel(request->job_id());
  if (!job.ok()) return to_grpc(job.status());
  *reply = std::move(*job);
  return grpc::Status::OK;
}

grpc::Status MeshingService::ListArtifacts(grpc::ServerContext* context,
                                           const v1::ListArtifactsRequest* request,
                                           v1::ListArtifactsReply* reply) {
  auto identity = identify(*context, "ListArtifacts");
  if (!identity.ok()) return to_grpc(identity.status());
  LABELMESH_RETURN_IF_ERROR(authorize(*identity, request->job_id()));
  auto artifacts = store_.artifacts(request->job_id());
  if (!artifacts.ok()) return to_grpc(artifacts.status());
  for (auto& artifact : *artifacts) *reply->add_artifacts() = std::move(artifact);
  return grpc::Status::OK;
}

grpc::Status MeshingService::Fetch(grpc::ServerContext* context, const v1::FetchRequest* request,
                                   grpc::ServerWriter<v1::FetchChunk>* writer) {
  auto identity = identify(*context, "Fetch");
  if (!identity.ok()) return to_grpc(identity.status());
  LABELMESH_RETURN_IF_ERROR(authorize(*identity, request->job_id()));
  auto artifacts = store_.artifacts(request->job_id());
  if (!artifacts.ok()) return to_grpc(artifacts.status());
  // Only names the job recorded are served: nothing else in the spool is reachable.
  const v1::Artifact* artifact = nullptr;
  for (const auto& candidate : *artifacts) {
    if (candidate.name() == request->artifact()) artifact = &candidate;
  }
  if (artifact == nullptr) {
    return grpc::Status(grpc::StatusCode::NOT_FOUND,
                        absl::StrCat("job has no artifact '", request->artifact(), "'"));
  }
  auto job = store_.get(request->job_id());
  if (!job.ok()) return to_grpc(job.status());
  std::ifstream in(store_.artifact_path(*job, artifact->name()), std::ios::binary);
  if (!in) return grpc::Status(grpc::StatusCode::NOT_FOUND, "the artifact expired or was removed");
  auto stream = open_stream(*context, *identity);
  if (!stream.ok()) return to_grpc(stream.status());
  auto ticket = watchdog_.watch(context, config_.stream_idle_timeout, config_.transfer_deadline,
                                "fetch", transfer_rate());
  v1::FetchChunk chunk;
  *chunk.mutable_artifact() = *artifact;
  std::string buffer(kChunkBytes, '\0');
  uint64_t sent = 0;
  do {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    chunk.set_data(buffer.data(), static_cast<size_t>(in.gcount()));
    if (!writer->Write(chunk))
      return stalled_or(*ticket, grpc::Status(grpc::StatusCode::CANCELLED, "reader left"));
    sent += chunk.data().size();
    ticket->touch(sent);
    chunk.clear_artifact();
  } while (in);
  return grpc::Status::OK;
}

grpc::Status MeshingService::DeleteJob(grpc::ServerContext* context,
                                       const v1::DeleteJobRequest* request,
                                       v1::DeleteJobReply* reply) {
  auto identity = identify(*context, "DeleteJob");
  if (!identity.ok()) return to_grpc(identity.status());
  LABELMESH_RETURN_IF_ERROR(authorize(*identity, request->job_id()));
  auto state = store_.remove(request->job_id());
  if (!state.ok()) return to_grpc(state.status());
  audit_.record({.event = "deleted",
                 .job_id = request->job_id(),
                 .identity = identity->name,
                 .peer = peer_host(context->peer()),
                 .call = "DeleteJob"});
  reply->set_state(*state);
  return grpc::Status::OK;
}

}  // namespace labelmesh::server
