// SPDX-License-Identifier: AGPL-3.0-or-later
// `labelmesh submit FILE --out DIR`: upload a volume to labelmeshd, follow the
// job, fetch its results. The same pipeline flags as `labelmesh mesh`.
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/job_follow.h"
#include "client/label_warnings.h"
#include "client/pipeline_options.h"
#include "client/report_table.h"
#include "client/server_connection.h"
#include "core/digest/sha256.h"
#include "core/header/volume_header.h"
#include "core/job/job_options.h"
#include "core/pipeline/report.h"
#include "core/util/status_macros.h"
#include "labelmesh/v1/service.grpc.pb.h"

namespace labelmesh::client {
namespace {

constexpr size_t kChunkBytes = 1 << 20;

struct SubmitFlags {
  std::string path;
  std::string out_dir;
  PipelineFlags pipeline;
  ConnectionFlags connection;
  bool detach = false;
  bool json = false;
  bool keep_input = false;
  std::string request_id;
  int retries = 5;
};

// A fresh request id: 32 random hex digits.
std::string random_request_id() {
  std::random_device random;
  std::string id;
  for (int i = 0; i < 4; ++i) id += absl::StrFormat("%08x", random());
  return id;
}

// Worth another try with the same request id: the server went away or the
// first try is still being received.
bool retryable(const absl::Status& status) {
  return status.code() == absl::StatusCode::kUnavailable ||
         status.code() == absl::StatusCode::kAborted;
}

// How long to wait before try `attempt` + 2: 1, 2, 4, ... s, at most 30 s,
// each with up to half as much again at random, so that clients cut off
// together (a NATS restart, say) do not all come back at once.
std::chrono::milliseconds retry_delay(int attempt) {
  const int64_t base = std::min<int64_t>(int64_t{1000} << std::min(attempt, 5), 30'000);
  static thread_local std::mt19937_64 random{std::random_device{}()};
  std::uniform_int_distribution<int64_t> extra(0, base / 2);
  return std::chrono::milliseconds(base + extra(random));
}

// The upload's percentage and rate on a terminal.
void print_upload_progress(uint64_t sent, uint64_t total, double seconds) {
  if (isatty(STDERR_FILENO) != 1) return;
  std::fprintf(stderr, "\r  %-20s %3d %%  %7.1f MB/s", "upload",
               total ? static_cast<int>(100 * sent / total) : 100,
               seconds > 0 ? sent / seconds / 1e6 : 0.0);
  if (sent == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

absl::StatusOr<v1::SubmitReply> upload_once(const ServerConnection& connection,
                                            const SubmitFlags& flags,
                                            const std::string& request_id) {
  LABELMESH_ASSIGN_OR_RETURN(auto digest, digest::sha256_file(flags.path));
  std::error_code error;
  const uint64_t size = std::filesystem::file_size(flags.path, error);
  if (error) return absl::NotFoundError(absl::StrCat(flags.path, ": ", error.message()));

  auto stub = v1::MeshingService::NewStub(connection.channel());
  auto context = connection.context();
  v1::SubmitReply reply;
  auto writer = stub->Submit(context.get(), &reply);
  v1::SubmitRequest request;
  v1::JobSpec& spec = *request.mutable_spec();
  LABELMESH_ASSIGN_OR_RETURN(auto options, to_mesh_options(flags.pipeline));
  *spec.mutable_options() = options;
  // The server knows a format by its name's extension: a DICOM file named
  // otherwise (dcmqi's label.seg, a PACS file) is sent as one.
  std::string file_name = std::filesystem::path(flags.path).filename().string();
  if (!volume::format_from_path(file_name) && volume::is_dicom_file(flags.path))
    file_name += ".dcm";
  spec.set_file_name(file_name);
  spec.set_size_bytes(size);
  spec.set_sha256(digest);
  spec.set_keep_input(flags.keep_input);
  spec.set_request_id(request_id);
  const auto start = std::chrono::steady_clock::now();
  bool open = writer->Write(request);
  std::ifstream in(flags.path, std::ios::binary);
  std::string buffer(kChunkBytes, '\0');
  uint64_t sent = 0;
  while (open && in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto count = static_cast<size_t>(in.gcount());
    if (count == 0) break;
    request.set_chunk(buffer.data(), count);
    open = writer->Write(request);
    sent += count;
    print_upload_progress(
        sent, size,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  writer->WritesDone();
  if (auto status = writer->Finish(); !status.ok()) return from_grpc(status);
  return reply;
}

// Uploads, retrying with the same request id so that a retry never makes a
// second job.
absl::StatusOr<v1::SubmitReply> upload(const ServerConnection& connection,
                                       const SubmitFlags& flags) {
  const std::string request_id = flags.request_id.empty() ? random_request_id() : flags.request_id;
  for (int attempt = 0;; ++attempt) {
    auto reply = upload_once(connection, flags, request_id);
    if (reply.ok() || !retryable(reply.status()) || attempt >= flags.retries) return reply;
    std::fprintf(stderr, "labelmesh submit: %s; trying again\n",
                 std::string(reply.status().message()).c_str());
    std::this_thread::sleep_for(retry_delay(attempt));
  }
}

int run_submit(const SubmitFlags& flags) {
  auto options = to_mesh_options(flags.pipeline);
  auto params =
      options.ok() ? params_from_options(*options) : absl::StatusOr<MeshParams>(options.status());
  if (!params.ok()) {
    std::fprintf(stderr, "labelmesh submit: %s\n", std::string(params.status().message()).c_str());
    return kExitUsage;
  }
  auto connection = ServerConnection::open(flags.connection);
  if (!connection.ok()) {
    std::fprintf(stderr, "labelmesh submit: %s\n",
                 std::string(connection.status().message()).c_str());
    return kExitUsage;
  }
  auto reply = upload(*connection, flags);
  if (!reply.ok()) {
    std::fprintf(stderr, "labelmesh submit: %s\n", std::string(reply.status().message()).c_str());
    return reply.status().code() == absl::StatusCode::kNotFound
               ? kExitBadInput
               : exit_code_for_call(reply.status());
  }
  if (flags.detach) {
    if (flags.json) {
      std::printf("{\"job_id\": \"%s\", \"queue_position\": %u}\n", reply->job_id().c_str(),
                  reply->queue_position());
    } else {
      std::printf("%s\n", reply->job_id().c_str());
    }
    return kExitSuccess;
  }
  if (!flags.json) std::fprintf(stderr, "job %s\n", reply->job_id().c_str());
  auto job = follow_job(*connection, reply->job_id(), FollowOptions{.json = false});
  if (!job.ok()) {
    std::fprintf(stderr, "labelmesh submit: %s\n", std::string(job.status().message()).c_str());
    return exit_code_for_call(job.status());
  }
  if (job->state() != v1::JOB_STATE_SUCCEEDED) return exit_code_for_job(*job);
  auto written = fetch_artifacts(*connection, reply->job_id(), flags.out_dir);
  if (!written.ok()) {
    std::fprintf(stderr, "labelmesh submit: %s\n", std::string(written.status().message()).c_str());
    return exit_code_for_call(written.status());
  }
  if (flags.json) {
    std::printf("%s\n", to_json(job->report()).c_str());
  } else {
    std::printf("%s", report_table(job->report()).c_str());
    std::printf("job %s finished: %d files written to %s\n", reply->job_id().c_str(), *written,
                flags.out_dir.c_str());
  }
  print_label_warnings("submit", job->report());
  return kExitSuccess;
}

}  // namespace

CommandRunner add_submit_command(CLI::App& app) {
  auto flags = std::make_shared<SubmitFlags>();
  CLI::App* submit = app.add_subcommand("submit", "Mesh a label volume on a labelmeshd server");
  submit
      ->add_option("file", flags->path,
                   "Label volume held in one file (.nii .nii.gz .mha .nrrd .inr .inr.gz .vti .dcm)")
      ->required();
  submit->add_option("--out", flags->out_dir, "Where the results are fetched to");
  add_pipeline_flags(*submit, flags->pipeline);
  add_connection_flags(*submit, flags->connection);
  submit->add_flag("--detach", flags->detach, "Print the job id once accepted and return");
  submit->add_flag("--keep-input", flags->keep_input,
                   "Keep the uploaded volume on the server until the job is deleted or expires "
                   "(by default it is deleted when the job ends)");
  submit->add_option("--request-id", flags->request_id,
                     "Id that makes the submit safe to repeat: the server answers a repeat with "
                     "the same job (default: a random id for this run's retries)");
  submit
      ->add_option("--retries", flags->retries,
                   "Tries again this many times while the server is unavailable")
      ->capture_default_str();
  submit->add_flag("--json", flags->json,
                   "Print the report (or, with --detach, the job id) as JSON on stdout");
  submit->footer(kExitCodeHelp);
  return [flags] {
    if (!flags->detach && flags->out_dir.empty()) {
      std::fprintf(stderr, "labelmesh submit: --out is required unless --detach\n");
      return int{kExitUsage};
    }
    return run_submit(*flags);
  };
}

}  // namespace labelmesh::client
