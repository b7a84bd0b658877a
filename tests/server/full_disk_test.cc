// SPDX-License-Identifier: AGPL-3.0-or-later
// The service on a spool disk that fills up: uploads are refused with "spool
// disk full", health says NOT_SERVING, and no accepted job is lost, also
// across a restart on the still full disk.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include "absl/strings/match.h"
#include "core/volume/phantom.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "server/metrics.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using testing::ServiceHarness;

bool serving(ServiceHarness& service) {
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(service.server().port()),
                                     grpc::InsecureChannelCredentials());
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  grpc::health::v1::HealthCheckResponse reply;
  const grpc::Status status = stub->Check(&context, grpc::health::v1::HealthCheckRequest(), &reply);
  return status.ok() && reply.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

bool has_metric(ServiceHarness& service, const std::string& line) {
  return service.server().metrics().text().find(line) != std::string::npos;
}

class FullDiskTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    spool_ = dir_ / "spool";
    input_ = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
  }
  void TearDown() override {
    if (limited_) {
      ::setrlimit(RLIMIT_FSIZE, &file_size_before_);
      std::signal(SIGXFSZ, SIG_DFL);
    }
    if (mounted_) ::umount2(spool_.c_str(), MNT_DETACH);
  }

  // The tmpfs filled to the last byte, or files limited to 64 bytes.
  void fill_the_disk() {
    if (mounted_) {
      std::ofstream filler(spool_ / "filler", std::ios::binary);
      const std::string block(64 << 10, 'x');
      while (filler.write(block.data(), std::streamsize(block.size())) && filler.flush()) {
      }
      filler.close();
      std::ofstream(spool_ / "filler-small", std::ios::binary) << std::string(4096, 'x');
      return;
    }
    std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &file_size_before_);
    const rlimit tiny{64, file_size_before_.rlim_max};
    limited_ = ::setrlimit(RLIMIT_FSIZE, &tiny) == 0;
    ASSERT_TRUE(limited_) << "neither a tmpfs nor a file size limit could fill the disk";
  }

  fs::path dir_, spool_, input_;
  bool mounted_ = false;
  bool limited_ = false;
  rlimit file_size_before_{};
};

TEST_F(FullDiskTest, UnderTheReserveUploadsAreRefusedAndHealthIsNotServing) {
  auto config = ServiceHarness::config_for(spool_);
  config.spool_reserve_bytes = uint64_t{1} << 60;  // More than any disk has free.
  ServiceHarness service(config);
  EXPECT_FALSE(serving(service));
  v1::SubmitReply reply;
  const grpc::Status refused = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StartsWith(refused.error_message(), "spool disk full"))
      << refused.error_message();
  EXPECT_EQ(testing::entries_in(spool_ / "jobs"), 0u);
  EXPECT_EQ(testing::entries_in(spool_ / "uploads"), 0u);
  EXPECT_TRUE(has_metric(service, "labelmesh_rejections_total{reason=\"disk_full\"} 1"));
  EXPECT_TRUE(has_metric(service, "labelmesh_spool_disk_pressure 1"));
}

// The drill: three queued jobs on a small tmpfs spool, the disk filled, every
// job cancelled, then a restart on the still full disk. Where mount is not
// allowed (not root), a file size limit on this process stands in for the
// full disk: every record write then fails with EFBIG, which the spool
// reports as it does ENOSPC.
TEST_F(FullDiskTest, NoAcceptedJobIsLostWhenTheDiskFills) {
  fs::create_directories(spool_);
  mounted_ = ::mount("tmpfs", spool_.c_str(), "tmpfs", 0, "size=8m") == 0;
  auto config = ServiceHarness::config_for(spool_);
  config.workers = 0;  // The jobs stay queued.
  config.spool_reserve_bytes = 0;
  config.max_job_output_bytes = 1 << 20;
  std::vector<std::string> jobs;
  {
    ServiceHarness service(config);
    for (int i = 0; i < 3; ++i) {
      v1::SubmitReply reply;
      ASSERT_THAT(service.submit(input_, testing::repaired_options(), &reply), testing::IsOk());
      jobs.push_back(reply.job_id());
    }
    fill_the_disk();
    for (const auto& id : jobs) {
      auto context = service.context();
      v1::CancelRequest request;
      request.set_job_id(id);
      v1::Job job;
      const grpc::Status status = service.stub().Cancel(context.get(), request, &job);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << id;
      EXPECT_TRUE(absl::StartsWith(status.error_message(), "spool disk full"))
          << status.error_message();
      // Where the spool lives on the server is not the client's to see.
      EXPECT_FALSE(absl::StrContains(status.error_message(), spool_.string()))
          << status.error_message();
      EXPECT_EQ(service.get(id).state(), v1::JOB_STATE_QUEUED)
          << "a cancel that was not saved took effect";
    }
    v1::SubmitReply reply;
    const grpc::Status refused = service.submit(input_, testing::repaired_options(), &reply);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_TRUE(absl::StrContains(refused.error_message(), "spool disk full"))
        << refused.error_message();
    EXPECT_FALSE(absl::StrContains(refused.error_message(), spool_.string()))
        << refused.error_message();
    EXPECT_TRUE(has_metric(service, "labelmesh_spool_write_failures_total 3"));
    service.shutdown();
  }
  // A restart on the full disk finds every job, still queued.
  ServiceHarness again(config);
  for (const auto& id : jobs) {
    grpc::Status status;
    const v1::Job job = again.get(id, &status);
    ASSERT_TRUE(status.ok()) << id << " lost: " << status.error_message();
    EXPECT_EQ(job.state(), v1::JOB_STATE_QUEUED);
  }
  EXPECT_EQ(testing::entries_in(spool_ / "quarantine"), 0u);
  again.shutdown();
}

// A queued job meets a disk with no room for its results: it waits in the
// queue, its attempts not counted, and runs once there is room.
TEST_F(FullDiskTest, QueuedJobsWaitForRoomInsteadOfFailing) {
  auto config = ServiceHarness::config_for(spool_);
  config.workers = 0;
  std::string id;
  {
    ServiceHarness service(config);
    v1::SubmitReply reply;
    ASSERT_THAT(service.submit(input_, testing::repaired_options(), &reply), testing::IsOk());
    id = reply.job_id();
    service.shutdown();
  }
  config.workers = 1;
  {
    config.spool_reserve_bytes = uint64_t{1} << 60;  // More than any disk has free.
    ServiceHarness full(config);
    std::this_thread::sleep_for(std::chrono::seconds(3));
    const v1::Job waiting = full.get(id);
    EXPECT_EQ(waiting.state(), v1::JOB_STATE_QUEUED) << waiting.error().message();
    EXPECT_EQ(waiting.attempts(), 0u);
    EXPECT_EQ(waiting.queue_position(), 0u);  // next
    full.shutdown();
  }
  config.spool_reserve_bytes = 0;
  ServiceHarness room(config);
  const auto events = room.watch(id);
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.back().has_finished());
  const v1::Job done = room.get(id);
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error().message();
  EXPECT_EQ(done.attempts(), 1u);
  room.shutdown();
}

}  // namespace
}  // namespace labelmesh
