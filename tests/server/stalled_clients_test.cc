// SPDX-License-Identifier: AGPL-3.0-or-later
// One client must not deny service to everyone: uploads that stall are
// dropped and free their slots, and a client holds at most so many streams.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "absl/strings/match.h"
#include "server/metrics.h"
#include "server/sha256.h"
#include "support/service_harness.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using testing::ServiceHarness;

class StalledClientsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    config_ = ServiceHarness::config_for(dir_ / "spool");
    input_ = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
  }

  fs::path dir_, input_;
  server::ServerConfig config_;
};

// A Submit stream that sends its spec, or nothing at all, and then waits.
struct StalledUpload {
  grpc::ClientContext context;
  v1::SubmitReply reply;
  std::unique_ptr<grpc::ClientWriter<v1::SubmitRequest>> writer;

  StalledUpload(ServiceHarness& service, const std::string& bytes, bool send_spec) {
    writer = service.stub().Submit(&context, &reply);
    if (!send_spec) return;
    v1::SubmitRequest request;
    request.mutable_spec()->set_file_name("stalled.nii.gz");
    request.mutable_spec()->set_size_bytes(bytes.size());
    request.mutable_spec()->set_sha256(digest::sha256_hex(bytes));
    writer->Write(request);
  }
};

TEST_F(StalledClientsTest, StalledUploadsAreDroppedAndFreeTheirSlots) {
  config_.max_concurrent_uploads = 2;
  config_.stream_idle_timeout = absl::Seconds(1);
  ServiceHarness service(config_);
  const std::string bytes = testing::read_bytes(input_);
  StalledUpload after_spec(service, bytes, true);
  StalledUpload silent(service, bytes, false);
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  // Both upload slots were taken; the watchdog has freed them.
  v1::SubmitReply reply;
  const grpc::Status status = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_TRUE(status.ok()) << status.error_message();
  for (StalledUpload* stalled : {&after_spec, &silent}) {
    stalled->writer->WritesDone();
    EXPECT_FALSE(stalled->writer->Finish().ok());
  }
  // Both count as stalled: the one that never sent its spec too.
  EXPECT_NE(
      service.server().metrics().text().find("labelmesh_rejections_total{reason=\"stalled\"} 2"),
      std::string::npos);
}

TEST_F(StalledClientsTest, AClientHoldsAtMostItsStreams) {
  config_.workers = 0;  // the job stays queued: its watchers wait
  config_.max_streams_per_client = 2;
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_TRUE(service.submit(input_, testing::repaired_options(), &reply).ok());
  v1::WatchRequest request;
  request.set_job_id(reply.job_id());
  grpc::ClientContext first_context, second_context;
  auto first = service.stub().Watch(&first_context, request);
  auto second = service.stub().Watch(&second_context, request);
  v1::JobEvent event;
  ASSERT_TRUE(first->Read(&event));  // both watches are open on the server
  ASSERT_TRUE(second->Read(&event));

  grpc::ClientContext third_context;
  auto third = service.stub().Watch(&third_context, request);
  EXPECT_FALSE(third->Read(&event));
  const grpc::Status refused = third->Finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StrContains(refused.error_message(), "most streams"))
      << refused.error_message();

  // Closing one frees its place.
  first_context.TryCancel();
  first->Finish();
  grpc::Status again;
  for (int tries = 0; tries < 50; ++tries) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(300));
    auto watch = service.stub().Watch(&context, request);
    const bool read = watch->Read(&event);
    again = watch->Finish();
    if (read) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(again.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << again.error_message();
  second_context.TryCancel();
  second->Finish();
}

size_t threads_of_this_process() {
  size_t count = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/task"))
    ++count;
  return count;
}

// Watches on the callback API: a watcher waiting for news holds no server
// thread, so a hundred of them add a few threads, not a hundred.
TEST_F(StalledClientsTest, WaitingWatchersHoldNoThreads) {
  config_.workers = 0;  // the job stays queued: its watchers wait
  config_.max_streams_per_client = 200;
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_TRUE(service.submit(input_, testing::repaired_options(), &reply).ok());
  v1::WatchRequest request;
  request.set_job_id(reply.job_id());
  // Client and server share this process: count before the first watch.
  const size_t before = threads_of_this_process();
  constexpr int kWatchers = 100;
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientReader<v1::JobEvent>>> readers;
  v1::JobEvent event;
  for (int i = 0; i < kWatchers; ++i) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    readers.push_back(service.stub().Watch(contexts.back().get(), request));
    ASSERT_TRUE(readers.back()->Read(&event));  // open on the server: its "queued" came
  }
  const size_t during = threads_of_this_process();
  EXPECT_LT(during, before + kWatchers / 4)
      << before << " threads before, " << during << " with " << kWatchers << " watchers";
  for (int i = 0; i < kWatchers; ++i) {
    contexts[i]->TryCancel();
    readers[i]->Finish();
  }
}

}  // namespace
}  // namespace labelmesh
