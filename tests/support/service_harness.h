// SPDX-License-Identifier: AGPL-3.0-or-later
// A labelmeshd in this process on a free loopback port, with a stub to call
// it, for tests of the service's contract.
#pragma once

#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/digest/sha256.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "labelmesh/v1/service.grpc.pb.h"
#include "server/labelmesh_server.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::testing {

// Files under `dir`, recursively (regular files only).
inline size_t count_files(const std::filesystem::path& dir) {
  size_t count = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir, error)) {
    if (entry.is_regular_file()) ++count;
  }
  return count;
}

// The phantom as dir/phantom.nii.gz.
inline std::filesystem::path write_phantom(const std::filesystem::path& dir,
                                           volume::PhantomShape shape, double scale = 1.0) {
  const std::filesystem::path path = dir / "phantom.nii.gz";
  auto status =
      volume::write_label_volume(volume::make_phantom(shape, scale).volume, path.string());
  EXPECT_THAT(status, testing::IsOk());
  return path;
}

// The quickest job: the repaired surface, no Poisson.
inline v1::MeshOptions repaired_options() {
  v1::MeshOptions options;
  options.set_surface(v1::SURFACE_METHOD_REPAIRED);
  return options;
}

class ServiceHarness {
 public:
  // A server on `spool`, with the config the test tuned.
  static server::ServerConfig config_for(const std::filesystem::path& spool) {
    server::ServerConfig config;
    config.listen = "127.0.0.1:0";
    config.spool_dir = spool.string();
    config.workers = 1;
    config.queue_capacity = 8;
    config.shutdown_grace = absl::Seconds(5);
    config.worker_executable = LABELMESH_WORKER;
    // Small, so that the tests run on a nearly full disk too.
    config.spool_reserve_bytes = 1 << 20;
    config.max_job_output_bytes = 256 << 20;
    return config;
  }

  explicit ServiceHarness(const server::ServerConfig& config) {
    auto started = server::LabelmeshServer::start(config);
    if (!started.ok()) throw std::runtime_error(std::string(started.status().message()));
    server_ = std::move(*started);
    channel_ = grpc::CreateChannel("127.0.0.1:" + std::to_string(server_->port()),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::MeshingService::NewStub(channel_);
  }

  server::LabelmeshServer& server() { return *server_; }
  v1::MeshingService::Stub& stub() { return *stub_; }
  void shutdown() { server_->shutdown(); }

  std::unique_ptr<grpc::ClientContext> context() const {
    auto context = std::make_unique<grpc::ClientContext>();
    if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
    context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
    return context;
  }

  // Sends `spec` then `bytes` in chunks of `chunk` bytes.
  grpc::Status submit_raw(const v1::JobSpec& spec, const std::string& bytes, v1::SubmitReply* reply,
                          size_t chunk = 1 << 20) {
    auto ctx = context();
    auto writer = stub_->Submit(ctx.get(), reply);
    v1::SubmitRequest request;
    *request.mutable_spec() = spec;
    bool open = writer->Write(request);
    for (size_t at = 0; open && at < bytes.size(); at += chunk) {
      request.set_chunk(bytes.substr(at, chunk));
      open = writer->Write(request);
    }
    writer->WritesDone();
    return writer->Finish();
  }

  // Uploads a file with a correct spec.
  grpc::Status submit(const std::filesystem::path& path, const v1::MeshOptions& options,
                      v1::SubmitReply* reply) {
    const std::string bytes = read_bytes(path);
    v1::JobSpec spec;
    *spec.mutable_options() = options;
    spec.set_file_name(path.filename().string());
    spec.set_size_bytes(bytes.size());
    spec.set_sha256(digest::sha256_hex(bytes));
    return submit_raw(spec, bytes, reply);
  }

  // Every event until the job ends (or the stream fails).
  std::vector<v1::JobEvent> watch(const std::string& job_id, grpc::Status* status = nullptr) {
    auto ctx = context();
    v1::WatchRequest request;
    request.set_job_id(job_id);
    auto reader = stub_->Watch(ctx.get(), request);
    std::vector<v1::JobEvent> events;
    v1::JobEvent event;
    while (reader->Read(&event)) events.push_back(event);
    const grpc::Status finished = reader->Finish();
    if (status) *status = finished;
    return events;
  }

  v1::Job get(const std::string& job_id, grpc::Status* status = nullptr) {
    auto ctx = context();
    v1::GetJobRequest request;
    request.set_job_id(job_id);
    v1::Job job;
    const grpc::Status result = stub_->GetJob(ctx.get(), request, &job);
    if (status) *status = result;
    return job;
  }

  std::string token;

 private:
  std::unique_ptr<server::LabelmeshServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::MeshingService::Stub> stub_;
};

}  // namespace labelmesh::testing
