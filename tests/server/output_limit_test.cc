// SPDX-License-Identifier: AGPL-3.0-or-later
// A job's output limit: Submit refuses an upload the spool could not hold
// with that much output, a worker stops at a result file that reaches it,
// and results over it in all fail the job and leave nothing behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/volume/phantom.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using testing::ServiceHarness;

v1::MeshOptions every_surface_format() {
  v1::MeshOptions options = testing::repaired_options();
  for (const char* format : {"stl", "vtp", "ply", "obj", "off"}) options.add_formats(format);
  return options;
}

class OutputLimitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    input_ = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
  }

  // Submits the sphere on a server with this output limit and waits for the
  // job to end.
  v1::Job run_with_limit(uint64_t limit, const std::string& spool_name) {
    auto config = ServiceHarness::config_for(dir_ / spool_name);
    config.max_job_output_bytes = limit;
    ServiceHarness service(config);
    v1::SubmitReply reply;
    const grpc::Status submitted = service.submit(input_, every_surface_format(), &reply);
    EXPECT_TRUE(submitted.ok()) << submitted.error_message();
    service.watch(reply.job_id());
    v1::Job job = service.get(reply.job_id());
    artifacts_.clear();
    if (job.state() == v1::JOB_STATE_SUCCEEDED) {
      auto context = service.context();
      v1::ListArtifactsRequest request;
      request.set_job_id(reply.job_id());
      v1::ListArtifactsReply listed;
      EXPECT_THAT(service.stub().ListArtifacts(context.get(), request, &listed), testing::IsOk());
      artifacts_.assign(listed.artifacts().begin(), listed.artifacts().end());
    }
    outputs_left_ = count_files(dir_ / spool_name / "jobs" / reply.job_id(), "out-");
    service.shutdown();
    return job;
  }

  // Files under the job directory's entries whose names start with `prefix`.
  static int count_files(const fs::path& job_dir, const std::string& prefix) {
    int count = 0;
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(job_dir, error)) {
      if (!absl::StartsWith(entry.path().filename().string(), prefix)) continue;
      for (const auto& file : fs::recursive_directory_iterator(entry.path(), error))
        count += file.is_regular_file() ? 1 : 0;
    }
    return count;
  }

  fs::path dir_, input_;
  std::vector<v1::Artifact> artifacts_;
  int outputs_left_ = 0;
};

TEST_F(OutputLimitTest, SubmitRefusesWhatTheSpoolCouldNotHoldWithItsResults) {
  auto config = ServiceHarness::config_for(dir_ / "spool");
  config.max_job_output_bytes = uint64_t{1} << 60;  // More than any disk has free.
  ServiceHarness service(config);
  v1::SubmitReply reply;
  const grpc::Status refused = service.submit(input_, every_surface_format(), &reply);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StartsWith(refused.error_message(), "spool disk full"))
      << refused.error_message();
  EXPECT_TRUE(absl::StrContains(refused.error_message(), "results of up to 1152921504606846976"))
      << refused.error_message();
}

TEST_F(OutputLimitTest, AResultFileThatReachesTheLimitStopsTheWorker) {
  const v1::Job job = run_with_limit(2000, "spool");
  ASSERT_EQ(job.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(job.error().code(), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_TRUE(absl::StrContains(job.error().message(), "output limit of 2000 bytes"))
      << job.error().message();
  EXPECT_TRUE(absl::StrContains(job.error().message(), "SIGXFSZ")) << job.error().message();
  EXPECT_EQ(outputs_left_, 0) << "a failed job's partial results stayed in the spool";
}

TEST_F(OutputLimitTest, ResultsOverTheLimitInAllFailTheJobAndLeaveNothing) {
  const v1::Job whole = run_with_limit(0, "unlimited");
  ASSERT_EQ(whole.state(), v1::JOB_STATE_SUCCEEDED) << whole.error().message();
  uint64_t largest = 0, total = 0;
  for (const auto& artifact : artifacts_) {
    largest = std::max<uint64_t>(largest, artifact.size_bytes());
    total += artifact.size_bytes();
  }
  ASSERT_GT(total, largest + 1) << "the sphere needs more than one result file";
  // Every file fits under the limit; all of them together do not.
  const v1::Job over = run_with_limit(largest + 1, "limited");
  ASSERT_EQ(over.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(over.error().code(), int(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_TRUE(absl::StrContains(over.error().message(),
                                absl::StrCat("over the job's output limit of ", largest + 1)))
      << over.error().message();
  EXPECT_EQ(outputs_left_, 0);
}

}  // namespace
}  // namespace labelmesh
