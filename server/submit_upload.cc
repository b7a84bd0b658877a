// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/submit_upload.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/digest/sha256.h"
#include "core/job/job_options.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "server/refusal.h"
#include "server/upload_checks.h"
#include "server/worker_process.h"

namespace labelmesh::server {
namespace {

// Longest a worker may take to read an upload the server cannot decode.
constexpr std::chrono::milliseconds kVolumeCheckTime{120'000};
// How often a living upload's modification time is renewed while nothing is
// written to it; half the shortest --abandoned-upload-age.
constexpr std::chrono::seconds kUploadMarkInterval{10};

absl::Status bad_request(const std::string& message) {
  return refused(Refusal::kBadRequest, absl::InvalidArgumentError(message));
}

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
  UploadFile(const UploadFile&) = delete;
  UploadFile& operator=(const UploadFile&) = delete;
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

RequestsInFlight::Claim::Claim(RequestsInFlight& requests, std::pair<std::string, std::string> key)
    : requests_(requests), key_(std::move(key)) {
  absl::MutexLock lock(&requests_.mutex_);
  claimed_ = key_.second.empty() || requests_.claims_.insert(key_).second;
}

RequestsInFlight::Claim::~Claim() {
  if (!claimed_ || key_.second.empty()) return;
  absl::MutexLock lock(&requests_.mutex_);
  requests_.claims_.erase(key_);
}

absl::Status SubmitUpload::check_spool_space(uint64_t upload_bytes) const {
  const ServerConfig& config = services_.config;
  auto free = services_.store.free_bytes();
  if (!free.ok()) return free.status();
  // The job's results must fit too; what they will come to is not known
  // before the job runs, so its output limit stands for them.
  const uint64_t outputs = config.max_job_output_bytes;
  // Saturating: a huge limit must not wrap around to a small sum.
  const uint64_t needed = config.spool_reserve_bytes + upload_bytes;
  const bool fits =
      needed >= config.spool_reserve_bytes && *free >= needed && *free - needed >= outputs;
  if (!fits) {
    return refused(Refusal::kDiskFull, absl::ResourceExhaustedError(absl::StrCat(
                                           "spool disk full: ", *free, " bytes free, an upload of ",
                                           upload_bytes, " bytes and results of up to ", outputs,
                                           " bytes would leave less than the reserve of ",
                                           config.spool_reserve_bytes, "; try again later")));
  }
  return absl::OkStatus();
}

absl::Status SubmitUpload::receive(const v1::JobSpec& spec, const std::string& path,
                                   StreamWatchdog::Ticket& ticket) {
  // The spool's errors come marked disk_full or spool_error.
  FileWriter out;
  LABELMESH_RETURN_IF_ERROR(out.open(path));
  digest::Sha256 hash;
  uint64_t received = 0;
  v1::SubmitRequest message;
  while (reader_.Read(&message)) {
    ticket.touch(received + message.chunk().size());
    if (!message.has_chunk()) return bad_request("after the spec, every message must be a chunk");
    const std::string& chunk = message.chunk();
    if (chunk.size() > kChunkBytes) return bad_request("chunk: over 1 MiB");
    if (received + chunk.size() > spec.size_bytes()) {
      return bad_request(
          absl::StrCat("upload: more bytes than spec.size_bytes (", spec.size_bytes(), ")"));
    }
    LABELMESH_RETURN_IF_ERROR(out.append(chunk));
    hash.update(chunk);
    received += chunk.size();
  }
  LABELMESH_RETURN_IF_ERROR(ticket.cancellation());
  // The checks that follow are progress too, but move no bytes.
  ticket.end_transfer();
  LABELMESH_RETURN_IF_ERROR(out.finish());
  if (received < spec.size_bytes()) {
    return bad_request(absl::StrCat("upload: truncated, ", received, " of ", spec.size_bytes(),
                                    " bytes received"));
  }
  if (hash.hex_digest() != spec.sha256()) {
    return refused(Refusal::kBadDigest,
                   absl::InvalidArgumentError(
                       "upload: SHA-256 of the bytes received does not match spec.sha256"));
  }
  return absl::OkStatus();
}

absl::Status SubmitUpload::run(v1::SubmitReply& reply) {
  const ServerConfig& config = services_.config;
  JobStore& store = services_.store;
  // Refused before the upload, not after it has all been received.
  if (auto status = store.available(); !status.ok())
    return refused(Refusal::kStoreUnavailable, status);
  const ShareKeys keys = share_keys(identity_, context_.peer());
  LABELMESH_ASSIGN_OR_RETURN(auto stream, services_.streams.open(keys.client, keys.host));
  // The spec is the first step: a client that sends nothing is dropped too.
  auto ticket =
      services_.watchdog.watch(&context_, config.stream_idle_timeout, config.transfer_deadline,
                               "upload", services_.transfer_rate);
  // Shares of the upload slots: one client, or one host, cannot take them all.
  LABELMESH_ASSIGN_OR_RETURN(auto upload_slot, services_.uploads.open(keys.client, keys.host));
  v1::SubmitRequest first;
  if (!reader_.Read(&first) || !first.has_spec())
    return ticket->cancellation_or(bad_request("the first message must hold the job spec"));
  ticket->touch();
  v1::JobSpec spec = first.spec();
  auto checked = check_spec(spec, config);
  if (!checked.ok())
    return refused(refusal_of(checked.status(), Refusal::kBadRequest), checked.status());
  MeshParams params = *std::move(checked);
  // A retried Submit gets the job its first try made.
  RequestsInFlight::Claim claim(services_.requests, {identity_.name, spec.request_id()});
  if (!claim.claimed()) {
    return refused(
        Refusal::kRequestInProgress,
        absl::AbortedError("a Submit with this request_id is still in progress; retry later"));
  }
  if (!spec.request_id().empty()) {
    if (auto prior = store.find_request(identity_.name, spec.request_id())) {
      if (prior->sha256 != spec.sha256()) {
        return refused(Refusal::kRequestIdReused,
                       absl::AlreadyExistsError(
                           "spec.request_id: already used for an upload with another sha256"));
      }
      reply.set_job_id(prior->job_id);
      reply.set_queue_position(prior->queue_position);
      reply.set_existing(true);
      return absl::OkStatus();
    }
  }
  if (store.queue_full()) {
    return refused(Refusal::kQueueFull,
                   absl::ResourceExhaustedError("the job queue is full; try again later"));
  }
  LABELMESH_RETURN_IF_ERROR(check_spool_space(spec.size_bytes()));
  // The job's voxel limit is the smaller of the client's and the server's.
  const uint64_t asked = spec.options().max_voxels();
  const uint64_t voxel_limit =
      asked == 0 ? config.max_voxels : std::min<uint64_t>(asked, config.max_voxels);
  params.limits.max_voxels = voxel_limit;
  // The job keeps its options as the pipeline reads them, defaults filled in,
  // so that GetJob shows what the job runs with.
  *spec.mutable_options() = make_options(params);

  const std::string job_id = store.new_job_id_for(identity_.name, spec.request_id());
  const std::string extension = *upload_extension(spec.file_name());
  // DICOM surfaces take their patient and study from a DICOM SEG: refused
  // before the upload rather than by the worker.
  if (params.dicom_surfaces && extension != ".dcm") {
    return bad_request(
        absl::StrCat("spec.options.formats: dcm needs a DICOM SEG upload (.dcm), not ", extension));
  }
  UploadFile upload(store.upload_path(job_id, extension));
  LABELMESH_RETURN_IF_ERROR(receive(spec, upload.path(), *ticket));
  upload.mark_alive();
  auto geometry = check_uploaded_volume(upload.path(), voxel_limit, config.worker_memory_bytes);
  if (!geometry.ok()) return refused(Refusal::kBadVolume, geometry.status());
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
      return !context_.IsCancelled();
    };
    std::unique_lock reading(services_.volume_reader, std::defer_lock);
    while (!reading.try_lock_for(std::chrono::milliseconds(500))) {
      if (!keep_going()) return refused(Refusal::kStalled, absl::CancelledError("the client left"));
    }
    auto read = check_volume_in_worker(worker_executable(config), upload.path(), voxel_limit,
                                       params.limits.separate_overlapping,
                                       config.worker_memory_bytes, kVolumeCheckTime, keep_going);
    if (!read.ok()) return refused(Refusal::kBadVolume, read);
  }
  if (auto status = check_sizing_for_grid(params.poisson, *geometry); !status.ok())
    return bad_request(absl::StrCat("spec.options: ", status.message()));

  v1::JobRecord record;
  v1::Job& job = *record.mutable_job();
  job.set_job_id(job_id);
  job.set_created_at(unix_now());
  job.set_owner(identity_.name);
  // The options are kept once, in the job: GetJob shows them, the worker
  // reads them.
  *job.mutable_options() = std::move(*spec.mutable_options());
  spec.clear_options();
  // Only the extension of the client's file name is kept: names can hold
  // patient identifiers.
  spec.set_file_name(absl::StrCat("upload", extension));
  *record.mutable_spec() = spec;
  record.set_input_extension(extension);
  // A client that left (or the watchdog dropped) hears nothing: no job.
  if (context_.IsCancelled()) {
    return ticket->cancellation_or(
        refused(Refusal::kStalled, absl::CancelledError("the client left")));
  }
  // The store's refusals come marked queue_full or disk_full.
  LABELMESH_ASSIGN_OR_RETURN(auto position, store.accept(std::move(record), upload.path()));
  upload.keep();
  reply.set_job_id(job_id);
  reply.set_queue_position(position);
  services_.metrics.upload_bytes(spec.size_bytes());
  return absl::OkStatus();
}

}  // namespace labelmesh::server
