// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/job_follow.h"

#include <filesystem>
#include <fstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "client/exit_codes.h"
#include "client/terminal_progress.h"
#include "core/digest/sha256.h"
#include "core/pipeline/report.h"
#include "google/protobuf/util/json_util.h"
#include "labelmesh/v1/service.grpc.pb.h"

namespace labelmesh::client {
namespace {

bool has_ended(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

// Lines for people on stderr: live percentages on a terminal, and one line
// per finished stage everywhere (logs of unattended runs).
class EventPrinter {
 public:
  // The server sends one stage_finished per stage: the live line prints none.
  explicit EventPrinter(bool json) : json_(json), live_(!json, false) {}

  void print(const v1::JobEvent& event) {
    if (json_) {
      // One object per line (JSON Lines), so a pipe can read events as they come.
      std::string line;
      google::protobuf::util::JsonPrintOptions options;
      options.preserve_proto_field_names = true;
      (void)google::protobuf::util::MessageToJsonString(event, &line, options);
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
      return;
    }
    if (event.has_queued()) {
      std::fprintf(stderr, "queued at position %u\n", event.queued().position());
    } else if (event.has_started()) {
      std::fprintf(stderr, "started (attempt %u)\n", event.started().attempt());
    } else if (event.has_progress()) {
      const auto& progress = event.progress();
      live_.update({progress.stage(), progress.fraction(), progress.label(), progress.label_name(),
                    progress.label_index(), progress.label_count(), progress.labels_done()});
    } else if (event.has_stage_finished()) {
      live_.clear();
      std::fprintf(stderr, "  %-20s done %8.2f s\n", event.stage_finished().stage().c_str(),
                   event.stage_finished().seconds());
    } else if (event.has_failed()) {
      live_.clear();
      std::fprintf(stderr, "failed: %s\n", event.failed().message().c_str());
    } else if (event.has_cancelled()) {
      live_.clear();
      std::fprintf(stderr, "cancelled\n");
    }
  }

 private:
  bool json_;
  TerminalProgress live_;
};

// UNAVAILABLE: the server is down or on its way down. CANCELLED: a server
// that shuts down cancels the streams still open (this client never cancels
// its own watch).
bool worth_retrying(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
         status.error_code() == grpc::StatusCode::CANCELLED;
}

}  // namespace

absl::Status from_grpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), describe(status));
}

int exit_code_for_call(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kOk:
      return kExitSuccess;
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kNotFound:
      return kExitBadInput;
    case absl::StatusCode::kFailedPrecondition:
    case absl::StatusCode::kCancelled:
      return kExitFailure;
    default:
      return kExitService;
  }
}

int exit_code_for_job(const v1::Job& job) {
  if (job.state() == v1::JOB_STATE_SUCCEEDED) return kExitSuccess;
  if (job.state() == v1::JOB_STATE_FAILED &&
      job.error().code() == static_cast<int>(absl::StatusCode::kInvalidArgument)) {
    return kExitBadInput;
  }
  return kExitFailure;
}

absl::StatusOr<v1::Job> follow_job(const ServerConnection& connection, const std::string& job_id,
                                   const FollowOptions& options) {
  auto stub = v1::MeshingService::NewStub(connection.channel());
  EventPrinter printer(options.json);
  uint64_t last_sequence = 0;
  auto unreachable_since = std::chrono::steady_clock::now();
  for (;;) {
    auto context = connection.context();
    v1::WatchRequest request;
    request.set_job_id(job_id);
    auto reader = stub->Watch(context.get(), request);
    v1::JobEvent event;
    bool ended = false;
    while (reader->Read(&event)) {
      unreachable_since = std::chrono::steady_clock::now();
      // A reconnect replays the history: print only what is new.
      if (event.sequence() > last_sequence) {
        printer.print(event);
        last_sequence = event.sequence();
      }
      ended = event.has_finished() || event.has_failed() || event.has_cancelled();
    }
    const grpc::Status status = reader->Finish();
    if (status.ok() && ended) break;
    if (status.ok() || worth_retrying(status)) {
      if (std::chrono::steady_clock::now() - unreachable_since > options.reconnect_for) {
        return from_grpc(status.ok() ? grpc::Status(grpc::StatusCode::UNAVAILABLE, "no end")
                                     : status);
      }
      std::this_thread::sleep_for(std::chrono::seconds(1));
      continue;
    }
    return from_grpc(status);
  }
  auto context = connection.context(std::chrono::seconds(30));
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  if (auto status = stub->GetJob(context.get(), request, &job); !status.ok()) {
    return from_grpc(status);
  }
  if (!has_ended(job.state())) return absl::InternalError("the watch ended before the job");
  return job;
}

absl::StatusOr<int> fetch_artifacts(const ServerConnection& connection, const std::string& job_id,
                                    const std::string& out_dir,
                                    const std::optional<std::string>& only) {
  auto stub = v1::MeshingService::NewStub(connection.channel());
  v1::ListArtifactsRequest list_request;
  list_request.set_job_id(job_id);
  v1::ListArtifactsReply list;
  {
    auto context = connection.context(std::chrono::seconds(30));
    if (auto status = stub->ListArtifacts(context.get(), list_request, &list); !status.ok()) {
      return from_grpc(status);
    }
  }
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error) return absl::InvalidArgumentError(absl::StrCat("--out: cannot create ", out_dir));
  int written = 0;
  for (const auto& artifact : list.artifacts()) {
    if (only && artifact.name() != *only) continue;
    // Names come from the server: never let one climb out of out_dir.
    const std::filesystem::path relative(artifact.name());
    if (relative.is_absolute() || artifact.name().find("..") != std::string::npos) {
      return absl::DataLossError(absl::StrCat("server sent an unsafe name: ", artifact.name()));
    }
    const std::filesystem::path path = std::filesystem::path(out_dir) / relative;
    std::filesystem::create_directories(path.parent_path(), error);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return absl::InvalidArgumentError(absl::StrCat("cannot write ", path.string()));
    auto context = connection.context();
    v1::FetchRequest request;
    request.set_job_id(job_id);
    request.set_artifact(artifact.name());
    auto reader = stub->Fetch(context.get(), request);
    v1::FetchChunk chunk;
    digest::Sha256 hash;
    uint64_t size = 0;
    while (reader->Read(&chunk)) {
      out.write(chunk.data().data(), static_cast<std::streamsize>(chunk.data().size()));
      hash.update(chunk.data());
      size += chunk.data().size();
    }
    if (auto status = reader->Finish(); !status.ok()) return from_grpc(status);
    out.close();
    if (size != artifact.size_bytes() || hash.hex_digest() != artifact.sha256()) {
      return absl::DataLossError(
          absl::StrCat(artifact.name(), ": size or SHA-256 differs from the server's"));
    }
    ++written;
  }
  if (only && written == 0) return absl::NotFoundError(absl::StrCat("no artifact ", *only));
  return written;
}

}  // namespace labelmesh::client
