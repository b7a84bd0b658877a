// SPDX-License-Identifier: AGPL-3.0-or-later
// Who may see what: client identities from a clients file, jobs owned by the
// identity that submitted them, admins, DeleteJob, inputs deleted at the end,
// backed-off authentication, reflection behind authentication, and the
// audit log.
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_split.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "server/job_table.h"
#include "server/metrics.h"
#include "server/spool.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"

namespace labelmesh::testing {
namespace {

namespace fs = std::filesystem;

const std::string kAliceToken = "alice-token-0123456789";
const std::string kBobToken = "bob-token-0123456789ab";
const std::string kCarolToken = "carol-admin-token-01234";

class AccessControlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    spool_ = dir_ / "spool";
    config_ = ServiceHarness::config_for(spool_);
    const fs::path clients = dir_ / "clients";
    write_file(clients,
               "# name token [admin]\n"
               "alice " +
                   kAliceToken +
                   "\n"
                   "bob   " +
                   kBobToken +
                   "\n"
                   "\n"
                   "carol " +
                   kCarolToken + " admin\n");
    config_.clients_file = clients.string();
    sphere_ = write_phantom(dir_, volume::PhantomShape::kSphere);
  }

  // Every RPC on `job_id` as the harness's current token; their codes.
  std::vector<grpc::StatusCode> codes_of_every_call(ServiceHarness& service,
                                                    const std::string& job_id) {
    std::vector<grpc::StatusCode> codes;
    grpc::Status status;
    service.get(job_id, &status);
    codes.push_back(status.error_code());
    service.watch(job_id, &status);
    codes.push_back(status.error_code());
    {
      auto ctx = service.context();
      v1::CancelRequest request;
      request.set_job_id(job_id);
      v1::Job job;
      codes.push_back(service.stub().Cancel(ctx.get(), request, &job).error_code());
    }
    {
      auto ctx = service.context();
      v1::ListArtifactsRequest request;
      request.set_job_id(job_id);
      v1::ListArtifactsReply reply;
      codes.push_back(service.stub().ListArtifacts(ctx.get(), request, &reply).error_code());
    }
    {
      auto ctx = service.context();
      v1::FetchRequest request;
      request.set_job_id(job_id);
      request.set_artifact("report.json");
      auto reader = service.stub().Fetch(ctx.get(), request);
      v1::FetchChunk chunk;
      while (reader->Read(&chunk)) {
      }
      codes.push_back(reader->Finish().error_code());
    }
    codes.push_back(delete_job(service, job_id).error_code());
    return codes;
  }

  grpc::Status delete_job(ServiceHarness& service, const std::string& job_id,
                          v1::DeleteJobReply* reply = nullptr) {
    auto ctx = service.context();
    v1::DeleteJobRequest request;
    request.set_job_id(job_id);
    v1::DeleteJobReply ignored;
    return service.stub().DeleteJob(ctx.get(), request, reply ? reply : &ignored);
  }

  std::vector<std::string> listed(ServiceHarness& service) {
    auto ctx = service.context();
    v1::ListJobsReply reply;
    EXPECT_THAT(service.stub().ListJobs(ctx.get(), {}, &reply), testing::IsOk());
    std::vector<std::string> ids;
    for (const auto& job : reply.jobs()) ids.push_back(job.job_id());
    return ids;
  }

  std::vector<std::string> audit_lines() const {
    return absl::StrSplit(read_bytes(spool_ / "audit.log"), '\n', absl::SkipEmpty());
  }

  fs::path dir_, spool_, sphere_;
  server::ServerConfig config_;
};

TEST_F(AccessControlTest, EachClientSeesOnlyItsOwnJobsAndAdminsSeeAll) {
  config_.workers = 0;  // jobs stay queued
  ServiceHarness service(config_);
  service.token = kAliceToken;
  v1::SubmitReply alices;
  ASSERT_THAT(service.submit(sphere_, repaired_options(), &alices), testing::IsOk());
  service.token = kBobToken;
  v1::SubmitReply bobs;
  ASSERT_THAT(service.submit(sphere_, repaired_options(), &bobs), testing::IsOk());

  // To Bob, Alice's job does not exist, whatever he calls.
  for (grpc::StatusCode code : codes_of_every_call(service, alices.job_id())) {
    EXPECT_EQ(code, grpc::StatusCode::NOT_FOUND);
  }
  EXPECT_EQ(listed(service), std::vector<std::string>{bobs.job_id()});
  service.token = kAliceToken;
  EXPECT_EQ(listed(service), std::vector<std::string>{alices.job_id()});
  grpc::Status status;
  EXPECT_EQ(service.get(alices.job_id(), &status).owner(), "alice");
  EXPECT_THAT(status, testing::IsOk());

  // Carol, an admin, sees both and can act on them.
  service.token = kCarolToken;
  EXPECT_EQ(listed(service).size(), 2u);
  EXPECT_EQ(service.get(bobs.job_id(), &status).owner(), "bob");
  EXPECT_THAT(status, testing::IsOk());
  v1::DeleteJobReply deleted;
  ASSERT_THAT(delete_job(service, bobs.job_id(), &deleted), testing::IsOk());
  EXPECT_EQ(deleted.state(), v1::JOB_STATE_QUEUED);
  EXPECT_FALSE(fs::exists(spool_ / "jobs" / bobs.job_id()));
  EXPECT_EQ(listed(service), std::vector<std::string>{alices.job_id()});
}

TEST_F(AccessControlTest, DeleteRemovesInputAndResultsAtOnce) {
  ServiceHarness service(config_);
  service.token = kAliceToken;
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(sphere_, repaired_options(), &reply), testing::IsOk());
  ASSERT_TRUE(service.watch(reply.job_id()).back().has_finished());
  const fs::path job_dir = spool_ / "jobs" / reply.job_id();
  ASSERT_GT(count_files(job_dir / "out-1"), 2u);

  v1::DeleteJobReply deleted;
  ASSERT_THAT(delete_job(service, reply.job_id(), &deleted), testing::IsOk());
  EXPECT_EQ(deleted.state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_FALSE(fs::exists(job_dir));
  grpc::Status status;
  service.get(reply.job_id(), &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(delete_job(service, reply.job_id()).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(AccessControlTest, ARunningJobDeletedIsStoppedAndGone) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ServiceHarness service(config_);
  service.token = kAliceToken;
  // The liver runs for several seconds: long enough to be deleted mid-run.
  v1::MeshOptions options;
  options.add_labels(255);
  v1::SubmitReply reply;
  ASSERT_THAT(service.submit(shared_data("liver.inr.gz"), options, &reply), testing::IsOk());
  for (int i = 0; i < 100 && service.get(reply.job_id()).state() != v1::JOB_STATE_RUNNING; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(service.get(reply.job_id()).state(), v1::JOB_STATE_RUNNING);
  v1::DeleteJobReply deleted;
  ASSERT_THAT(delete_job(service, reply.job_id(), &deleted), testing::IsOk());
  EXPECT_EQ(deleted.state(), v1::JOB_STATE_RUNNING);
  // Gone for clients at once; its files once the worker has stopped.
  grpc::Status status;
  service.get(reply.job_id(), &status);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(listed(service).empty());
  const fs::path job_dir = spool_ / "jobs" / reply.job_id();
  for (int i = 0; i < 40 && fs::exists(job_dir); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_FALSE(fs::exists(job_dir)) << "the worker was not stopped within 2 s";
  // Stopped, not left to finish: the job ended cancelled.
  EXPECT_NE(service.server().metrics().text().find("labelmesh_jobs_total{outcome=\"cancelled\"} 1"),
            std::string::npos);
}

TEST_F(AccessControlTest, TheInputIsDeletedWhenTheJobEndsUnlessKept) {
  ServiceHarness service(config_);
  service.token = kAliceToken;
  v1::SubmitReply dropped, kept;
  ASSERT_THAT(service.submit(sphere_, repaired_options(), &dropped), testing::IsOk());
  const std::string bytes = read_bytes(sphere_);
  v1::JobSpec spec;
  *spec.mutable_options() = repaired_options();
  spec.set_file_name("sphere.nii.gz");
  spec.set_size_bytes(bytes.size());
  spec.set_sha256(digest::sha256_hex(bytes));
  spec.set_keep_input(true);
  ASSERT_THAT(service.submit_raw(spec, bytes, &kept), testing::IsOk());
  ASSERT_TRUE(service.watch(dropped.job_id()).back().has_finished());
  ASSERT_TRUE(service.watch(kept.job_id()).back().has_finished());
  EXPECT_FALSE(fs::exists(spool_ / "jobs" / dropped.job_id() / "input.nii.gz"));
  EXPECT_TRUE(fs::exists(spool_ / "jobs" / kept.job_id() / "input.nii.gz"));
}

TEST_F(AccessControlTest, RepeatedFailedAuthenticationIsBackedOff) {
  config_.auth_failures_before_backoff = 3;
  config_.auth_first_backoff = absl::Seconds(1);
  ServiceHarness service(config_);
  auto list_code = [&service] {
    auto ctx = service.context();
    v1::ListJobsReply reply;
    return service.stub().ListJobs(ctx.get(), {}, &reply).error_code();
  };
  service.token = "wrong-token-0123456789";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(list_code(), grpc::StatusCode::UNAUTHENTICATED);
  // Backed off: a wrong token is refused unchecked for a second; the right
  // one is never held back.
  EXPECT_EQ(list_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  service.token = kAliceToken;
  EXPECT_EQ(list_code(), grpc::StatusCode::OK);
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  // A success does not clear the count: the next failure backs off again.
  service.token = "wrong-token-0123456789";
  EXPECT_EQ(list_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(list_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  service.token = kAliceToken;
  EXPECT_EQ(list_code(), grpc::StatusCode::OK);
  EXPECT_NE(
      service.server().metrics().text().find("labelmesh_rejections_total{reason=\"auth_backoff\"}"),
      std::string::npos);
  // Each failed authentication is audited; the backed-off calls are only
  // counted, so that a client hammering the server cannot fill the disk.
  EXPECT_EQ(audit_lines().size(), 4u);
}

// An attacker with no credentials on the same address as a valid client
// (behind an ingress or NAT, every client shares one) does not lock it out.
TEST_F(AccessControlTest, FailedLoginsDoNotLockOutAValidClientOnTheSameHost) {
  config_.auth_failures_before_backoff = 2;
  config_.auth_first_backoff = absl::Seconds(5);
  ServiceHarness service(config_);
  std::atomic<bool> done{false};
  std::atomic<int> attacker_calls{0}, attacker_backed_off{0};
  std::thread attacker([&] {
    while (!done) {
      grpc::ClientContext ctx;
      ctx.AddMetadata("authorization", "Bearer wrong-token-0123456789");
      ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
      v1::ListJobsReply reply;
      const auto code = service.stub().ListJobs(&ctx, {}, &reply).error_code();
      ++attacker_calls;
      if (code == grpc::StatusCode::RESOURCE_EXHAUSTED) ++attacker_backed_off;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  service.token = kAliceToken;
  int served = 0;
  for (int i = 0; i < 20; ++i) {
    auto ctx = service.context();
    v1::ListJobsReply reply;
    served += service.stub().ListJobs(ctx.get(), {}, &reply).ok();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  done = true;
  attacker.join();
  EXPECT_EQ(served, 20);
  EXPECT_GT(attacker_calls.load(), 5);
  EXPECT_GE(attacker_backed_off.load(), attacker_calls.load() - 2);
}

// The status of a reflection call carrying no request.
grpc::Status reflection_call_status(int port) {
  auto channel =
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue queue;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  auto call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &queue);
  void* tag = nullptr;
  bool ok = false;
  call->StartCall(reinterpret_cast<void*>(1));
  queue.Next(&tag, &ok);
  call->WritesDone(reinterpret_cast<void*>(2));
  queue.Next(&tag, &ok);
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(3));
  while (queue.Next(&tag, &ok) && tag != reinterpret_cast<void*>(3)) {
  }
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  return status;
}

TEST_F(AccessControlTest, ReflectionIsServedOnlyWithoutClientAuthentication) {
  {
    ServiceHarness authenticated(config_);
    EXPECT_EQ(reflection_call_status(authenticated.server().port()).error_code(),
              grpc::StatusCode::UNIMPLEMENTED);
  }
  config_.clients_file.clear();
  ServiceHarness anonymous(config_);
  EXPECT_NE(reflection_call_status(anonymous.server().port()).error_code(),
            grpc::StatusCode::UNIMPLEMENTED);
}

TEST_F(AccessControlTest, ARetriedSubmitWithTheSameRequestIdGetsTheSameJob) {
  config_.workers = 0;
  ServiceHarness service(config_);
  service.token = kAliceToken;
  const std::string bytes = read_bytes(sphere_);
  v1::JobSpec spec;
  *spec.mutable_options() = repaired_options();
  spec.set_file_name("sphere.nii.gz");
  spec.set_size_bytes(bytes.size());
  spec.set_sha256(digest::sha256_hex(bytes));
  spec.set_request_id("order-4711/attempt");
  v1::SubmitReply first, again;
  ASSERT_THAT(service.submit_raw(spec, bytes, &first), testing::IsOk());
  EXPECT_FALSE(first.existing());
  ASSERT_THAT(service.submit_raw(spec, bytes, &again), testing::IsOk());
  EXPECT_TRUE(again.existing());
  EXPECT_EQ(again.job_id(), first.job_id());
  EXPECT_EQ(listed(service).size(), 1u);

  // Another client's id is its own; the same id for other bytes is refused.
  service.token = kBobToken;
  v1::SubmitReply bobs;
  ASSERT_THAT(service.submit_raw(spec, bytes, &bobs), testing::IsOk());
  EXPECT_NE(bobs.job_id(), first.job_id());
  service.token = kAliceToken;
  spec.set_sha256(std::string(64, 'a'));
  v1::SubmitReply other;
  EXPECT_EQ(service.submit_raw(spec, bytes, &other).error_code(), grpc::StatusCode::ALREADY_EXISTS);
}

TEST_F(AccessControlTest, ListJobsPagesAndFiltersByState) {
  config_.workers = 0;
  ServiceHarness service(config_);
  service.token = kAliceToken;
  std::vector<std::string> submitted;
  for (int i = 0; i < 5; ++i) {
    v1::SubmitReply reply;
    ASSERT_THAT(service.submit(sphere_, repaired_options(), &reply), testing::IsOk());
    submitted.insert(submitted.begin(), reply.job_id());  // newest first
  }
  {
    auto ctx = service.context();
    v1::CancelRequest cancel;
    cancel.set_job_id(submitted[4]);
    v1::Job job;
    ASSERT_THAT(service.stub().Cancel(ctx.get(), cancel, &job), testing::IsOk());
  }
  std::vector<std::string> paged;
  v1::ListJobsRequest request;
  request.set_page_size(2);
  int pages = 0;
  do {
    auto ctx = service.context();
    v1::ListJobsReply reply;
    ASSERT_THAT(service.stub().ListJobs(ctx.get(), request, &reply), testing::IsOk());
    EXPECT_LE(reply.jobs_size(), 2);
    for (const auto& job : reply.jobs()) {
      paged.push_back(job.job_id());
      EXPECT_GT(job.created_time().seconds(), 1'600'000'000);
    }
    request.set_page_token(reply.next_page_token());
    ++pages;
  } while (!request.page_token().empty());
  EXPECT_EQ(paged, submitted);
  EXPECT_EQ(pages, 3);

  v1::ListJobsRequest cancelled;
  cancelled.add_states(v1::JOB_STATE_CANCELLED);
  auto ctx = service.context();
  v1::ListJobsReply reply;
  ASSERT_THAT(service.stub().ListJobs(ctx.get(), cancelled, &reply), testing::IsOk());
  ASSERT_EQ(reply.jobs_size(), 1);
  EXPECT_EQ(reply.jobs(0).job_id(), submitted[4]);

  v1::ListJobsRequest forged;
  forged.set_page_token("not-a-token");
  auto ctx2 = service.context();
  EXPECT_EQ(service.stub().ListJobs(ctx2.get(), forged, &reply).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(AccessControlTest, TheAuditLogHasALinePerJobAndNoHeaderText) {
  ServiceHarness service(config_);
  // A NIfTI whose description field holds a name: it must not reach the log.
  const fs::path named = dir_ / "named.nii";
  ASSERT_TRUE(volume::write_label_volume(
                  volume::make_phantom(volume::PhantomShape::kSphere, 1.0).volume, named.string())
                  .ok());
  std::string bytes = read_bytes(named);
  const std::string patient = "DOE^JANE 1970-01-01";
  bytes.replace(148, patient.size(), patient);
  write_file(named, bytes);
  const fs::path broken = dir_ / "broken.nii";
  write_file(broken, bytes.substr(0, 400));

  service.token = kAliceToken;
  v1::SubmitReply accepted, refused;
  ASSERT_THAT(service.submit(named, repaired_options(), &accepted), testing::IsOk());
  ASSERT_TRUE(service.watch(accepted.job_id()).back().has_finished());
  EXPECT_EQ(service.submit(broken, repaired_options(), &refused).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  ASSERT_THAT(delete_job(service, accepted.job_id()), testing::IsOk());
  service.token = "wrong-token-0123456789";
  EXPECT_EQ(service.submit(named, repaired_options(), &refused).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);

  const std::vector<std::string> lines = audit_lines();
  ASSERT_EQ(lines.size(), 4u);
  const std::string accepted_line =
      "\"event\":\"accepted\",\"job_id\":\"" + accepted.job_id() + "\",\"identity\":\"alice\"";
  EXPECT_TRUE(absl::StrContains(lines[0], accepted_line)) << lines[0];
  EXPECT_TRUE(absl::StrContains(lines[1], "\"event\":\"refused\"")) << lines[1];
  EXPECT_TRUE(
      absl::StrContains(lines[1], "\"code\":\"INVALID_ARGUMENT\",\"reason\":\"bad_volume\""))
      << lines[1];
  EXPECT_TRUE(absl::StrContains(lines[2], "\"event\":\"deleted\",\"job_id\":\"" +
                                              accepted.job_id() + "\",\"identity\":\"alice\""))
      << lines[2];
  EXPECT_TRUE(absl::StrContains(lines[3], "\"event\":\"unauthenticated\"")) << lines[3];
  for (const auto& line : lines) {
    // UTC, to the millisecond: "2026-01-31T12:34:56.789Z".
    EXPECT_EQ(line.substr(0, 9), "{\"time\":\"");
    EXPECT_EQ(line.substr(32, 2), "Z\"") << line;
    EXPECT_FALSE(absl::StrContains(line, "DOE")) << line;
  }
}

// A spool written before jobs had owners: its jobs belong to the anonymous
// client, so a server without authentication still shows them and one with
// authentication shows them to admins only.
TEST_F(AccessControlTest, JobsFromBeforeIdentitiesBelongToTheAnonymousClient) {
  const std::string id = server::new_job_id();
  {
    auto spool = server::Spool::open(spool_.string());
    ASSERT_THAT(spool, testing::IsOk());
    fs::create_directories(spool->job_dir(id));
    v1::JobRecord record;
    record.mutable_job()->set_job_id(id);
    record.mutable_job()->set_state(v1::JOB_STATE_CANCELLED);
    record.mutable_job()->set_created_at(server::unix_now());
    record.mutable_job()->set_finished_at(server::unix_now());
    ASSERT_THAT(spool->save(record), testing::IsOk());
  }
  {
    ServiceHarness authenticated(config_);
    authenticated.token = kAliceToken;
    grpc::Status status;
    authenticated.get(id, &status);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    authenticated.token = kCarolToken;
    EXPECT_EQ(authenticated.get(id, &status).owner(), "anonymous");
    EXPECT_THAT(status, testing::IsOk());
  }
  config_.clients_file.clear();
  ServiceHarness anonymous(config_);
  grpc::Status status;
  anonymous.get(id, &status);
  EXPECT_TRUE(status.ok()) << status.error_message();
}

}  // namespace
}  // namespace labelmesh::testing
