// SPDX-License-Identifier: AGPL-3.0-or-later
// One client must not deny service to everyone: uploads that stall or
// trickle are dropped and free their slots, and a client, and a client
// host, holds at most so many streams and uploads.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "absl/strings/match.h"
#include "core/digest/sha256.h"
#include "server/metrics.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using testing::ServiceHarness;

const std::string kAliceToken = "alice-token-0123456789";
const std::string kBobToken = "bob-token-0123456789ab";

class StalledClientsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    config_ = ServiceHarness::config_for(dir_ / "spool");
    input_ = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
  }

  // Two clients, alice and bob, each with a token of its own.
  void use_clients_file() {
    const fs::path clients = dir_ / "clients";
    testing::write_file(clients, "alice " + kAliceToken + "\nbob " + kBobToken + "\n");
    config_.clients_file = clients.string();
  }

  fs::path dir_, input_;
  server::ServerConfig config_;
};

std::string metrics_of(ServiceHarness& service) { return service.server().metrics().text(); }

// A Submit stream, with the harness's current token, that sends its spec,
// or nothing at all, and then waits.
struct StalledUpload {
  grpc::ClientContext context;
  v1::SubmitReply reply;
  std::unique_ptr<grpc::ClientWriter<v1::SubmitRequest>> writer;

  StalledUpload(ServiceHarness& service, const std::string& bytes, bool send_spec) {
    if (!service.token.empty()) context.AddMetadata("authorization", "Bearer " + service.token);
    writer = service.stub().Submit(&context, &reply);
    if (!send_spec) return;
    v1::SubmitRequest request;
    request.mutable_spec()->set_file_name("stalled.nii.gz");
    request.mutable_spec()->set_size_bytes(bytes.size());
    request.mutable_spec()->set_sha256(digest::sha256_hex(bytes));
    writer->Write(request);
  }

  // Ends the stream (the server refuses it as truncated, if it still holds
  // it); its status.
  grpc::Status finish() {
    writer->WritesDone();
    return writer->Finish();
  }
};

// A Watch on `job_id` with `token`, open on the server once its first event
// came (false if the server refused it: `finish()` says why).
struct OpenWatch {
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReader<v1::JobEvent>> reader;
  bool open = false;

  OpenWatch(ServiceHarness& service, const std::string& token, const std::string& job_id) {
    context.AddMetadata("authorization", "Bearer " + token);
    v1::WatchRequest request;
    request.set_job_id(job_id);
    reader = service.stub().Watch(&context, request);
    v1::JobEvent event;
    open = reader->Read(&event);
  }

  grpc::Status finish() {
    if (open) context.TryCancel();
    return reader->Finish();
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
  ASSERT_THAT(service.submit(input_, testing::repaired_options(), &reply), testing::IsOk());
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

// The caps count per identity and per host: one client at its streams does
// not hold back another on the same host, until the host is at its own cap.
TEST_F(StalledClientsTest, AnIdentitysStreamsDoNotCountAgainstAnother) {
  use_clients_file();
  config_.workers = 0;  // the jobs stay queued: their watchers wait
  config_.max_streams_per_client = 2;
  config_.max_streams_per_host = 3;
  ServiceHarness service(config_);
  v1::SubmitReply alices, bobs;
  service.token = kAliceToken;
  ASSERT_THAT(service.submit(input_, testing::repaired_options(), &alices), testing::IsOk());
  OpenWatch first(service, kAliceToken, alices.job_id());
  OpenWatch second(service, kAliceToken, alices.job_id());
  ASSERT_TRUE(first.open && second.open);
  OpenWatch third(service, kAliceToken, alices.job_id());
  EXPECT_FALSE(third.open);
  const grpc::Status refused = third.finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StrContains(refused.error_message(), "this client holds its most streams"))
      << refused.error_message();

  // bob's Submit and Watch take the host's last place.
  service.token = kBobToken;
  const grpc::Status submitted = service.submit(input_, testing::repaired_options(), &bobs);
  ASSERT_TRUE(submitted.ok()) << submitted.error_message();
  OpenWatch bobs_first(service, kBobToken, bobs.job_id());
  EXPECT_TRUE(bobs_first.open);
  OpenWatch bobs_second(service, kBobToken, bobs.job_id());
  EXPECT_FALSE(bobs_second.open);
  const grpc::Status host_full = bobs_second.finish();
  EXPECT_EQ(host_full.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(absl::StrContains(host_full.error_message(), "host holds its most streams"))
      << host_full.error_message();
  for (OpenWatch* watch : {&first, &second, &bobs_first}) watch->finish();
}

// Bytes that come too slowly keep an upload from stalling, not from being cut.
TEST_F(StalledClientsTest, TrickledUploadsAreCutBelowTheMinimumRate) {
  config_.min_transfer_rate = 64 << 10;
  config_.transfer_rate_window = absl::Seconds(1);
  config_.stream_idle_timeout = absl::Seconds(10);
  ServiceHarness service(config_);
  const std::string bytes = testing::read_bytes(input_);
  ASSERT_GT(bytes.size(), 20u);
  const absl::Time start = absl::Now();
  StalledUpload trickled(service, bytes, true);
  v1::SubmitRequest request;
  for (size_t at = 0; at < 15; ++at) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    request.set_chunk(bytes.substr(at, 1));
    if (!trickled.writer->Write(request)) break;
  }
  // The watchdog cancels the stream: the client sees CANCELLED, or the
  // handler's DEADLINE_EXCEEDED if that came first; the metric says why.
  const grpc::Status cut = trickled.finish();
  EXPECT_TRUE(cut.error_code() == grpc::StatusCode::CANCELLED ||
              cut.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED)
      << cut.error_code() << " " << cut.error_message();
  // Cut after its first window, long before the idle timeout.
  EXPECT_LT(absl::Now() - start, absl::Seconds(5));
  EXPECT_TRUE(
      absl::StrContains(metrics_of(service), "labelmesh_rejections_total{reason=\"too_slow\"} 1"))
      << metrics_of(service);

  // An upload at full speed is not cut.
  v1::SubmitReply reply;
  const grpc::Status status = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_TRUE(status.ok()) << status.error_message();
}

// One client, and one host, holds only its share of the upload slots.
TEST_F(StalledClientsTest, OneClientCannotTakeEveryUploadSlot) {
  use_clients_file();
  config_.max_concurrent_uploads = 4;
  config_.max_uploads_per_client = 2;
  config_.max_uploads_per_host = 3;
  config_.stream_idle_timeout = absl::Seconds(10);
  ServiceHarness service(config_);
  const std::string bytes = testing::read_bytes(input_);
  service.token = kAliceToken;
  StalledUpload alices_first(service, bytes, true);
  StalledUpload alices_second(service, bytes, true);
  // Both hold their slots on the server (the spec comes after the slot).
  std::this_thread::sleep_for(std::chrono::seconds(1));
  v1::SubmitReply reply;
  const grpc::Status third = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_EQ(third.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << third.error_message();
  EXPECT_TRUE(absl::StrContains(third.error_message(), "this client holds its most uploads"))
      << third.error_message();

  service.token = kBobToken;
  const grpc::Status bobs = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_TRUE(bobs.ok()) << bobs.error_message();
  // With bob's upload in progress the host holds 3: his next is refused.
  StalledUpload bobs_stalled(service, bytes, true);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const grpc::Status host_full = service.submit(input_, testing::repaired_options(), &reply);
  EXPECT_EQ(host_full.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << host_full.error_message();
  EXPECT_TRUE(absl::StrContains(host_full.error_message(), "host holds its most uploads"))
      << host_full.error_message();
  EXPECT_TRUE(absl::StrContains(metrics_of(service),
                                "labelmesh_rejections_total{reason=\"too_many_uploads\"} 2"))
      << metrics_of(service);
  for (StalledUpload* stalled : {&alices_first, &alices_second, &bobs_stalled})
    EXPECT_EQ(stalled->finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
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
  config_.max_streams_per_host = 200;
  ServiceHarness service(config_);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(input_, testing::repaired_options(), &reply), testing::IsOk());
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
