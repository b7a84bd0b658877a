// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmeshd's cluster roles against a real nats-server on loopback: the
// frontend's job store (request ids, replays, deletes, expiry) and what the
// health service tells probes. The whole cluster of processes, with its
// faults, is tests/server/cluster_drill_test.py.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "cluster/nats_server.h"
#include "core/job/job_options.h"
#include "core/volume/phantom.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "labelmesh/v1/service.grpc.pb.h"
#include "server/cluster/cluster_job_store.h"
#include "server/labelmesh_server.h"
#include "server/metrics.h"
#include "server/spool.h"
#include "support/service_harness.h"
#include "support/status_matchers.h"

namespace labelmesh {
namespace {
namespace fs = std::filesystem;
using server::ClusterJobStore;
using server::JobStore;

// Every event a listener heard, and whether it heard the end.
class RecordingListener final : public JobStore::EventListener {
 public:
  void on_event(const v1::JobEvent& event, bool last) override {
    std::lock_guard lock(mutex_);
    events_.push_back(event);
    ended_ = ended_ || last;
  }
  void on_closed(const absl::Status& status) override {
    std::lock_guard lock(mutex_);
    closed_ = status;
    ended_ = true;
  }
  bool ended() {
    std::lock_guard lock(mutex_);
    return ended_;
  }
  std::vector<v1::JobEvent> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  std::mutex mutex_;
  std::vector<v1::JobEvent> events_;
  absl::Status closed_;
  bool ended_ = false;
};

class ClusterRolesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    nats_ = std::make_unique<testing::NatsServer>(dir_ / "nats");
    cluster::ClusterSettings settings;
    settings.nats_url = nats_->url();
    settings.queue.ack_wait = absl::Seconds(5);
    connection_ = std::move(cluster::ClusterConnection::open(settings).value());
    files_ = std::make_unique<cluster::SharedArtifacts>(
        cluster::SharedArtifacts::open((dir_ / "artifacts").string()).value());
    store_ = std::make_unique<ClusterJobStore>(*connection_, *files_, 8, absl::Hours(1));
  }

  // A job accepted by the store from an upload of `bytes`.
  std::string accept(const std::string& owner, const std::string& request_id,
                     const std::string& bytes = "volume bytes") {
    const std::string id = store_->new_job_id_for(owner, request_id);
    const std::string upload = store_->upload_path(id, ".nii.gz");
    std::ofstream(upload, std::ios::binary) << bytes;
    v1::JobRecord record;
    record.mutable_job()->set_job_id(id);
    record.mutable_job()->set_owner(owner);
    record.mutable_job()->set_created_at(server::unix_now());
    record.mutable_spec()->set_request_id(request_id);
    record.mutable_spec()->set_sha256("digest of " + bytes);
    record.set_input_extension(".nii.gz");
    EXPECT_THAT(store_->accept(record, upload), testing::IsOk());
    return id;
  }

  // Claims and ends the job as a worker would.
  void finish(const std::string& id, v1::JobState state) {
    auto claim = connection_->jobs->claim(id).value();
    v1::JobRecord result;
    if (state == v1::JOB_STATE_SUCCEEDED) result.add_artifacts()->set_name("volume.vtu");
    ASSERT_THAT(connection_->jobs->finish(claim, state, result), testing::IsOk());
  }

  // A sphere phantom accepted as a frontend would, for a real worker to run.
  std::string accept_sphere() {
    const fs::path volume = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
    const std::string id = store_->new_job_id_for("ann", "");
    const std::string upload = store_->upload_path(id, ".nii.gz");
    fs::copy_file(volume, upload);
    v1::JobRecord record;
    record.mutable_job()->set_job_id(id);
    record.mutable_job()->set_owner("ann");
    record.mutable_job()->set_created_at(server::unix_now());
    // A frontend stores the options with every default filled in.
    *record.mutable_job()->mutable_options() = make_options(MeshParams{});
    record.set_input_extension(".nii.gz");
    EXPECT_THAT(store_->accept(record, upload), testing::IsOk());
    return id;
  }

  // The job once it has ended, or as it is after two minutes.
  v1::Job wait_until_ended(const std::string& id) {
    v1::Job job = store_->get(id).value();
    for (int i = 0; i < 1200 && !server::has_ended(job.state()); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      job = store_->get(id).value();
    }
    return job;
  }

  fs::path job_dir(const std::string& id) { return dir_ / "artifacts" / "jobs" / id; }

  fs::path dir_;
  std::unique_ptr<testing::NatsServer> nats_;
  std::unique_ptr<cluster::ClusterConnection> connection_;
  std::unique_ptr<cluster::SharedArtifacts> files_;
  std::unique_ptr<ClusterJobStore> store_;
};

TEST_F(ClusterRolesTest, ARetriedRequestIsOneJobOnAnyFrontend) {
  EXPECT_EQ(store_->new_job_id_for("ann", "r1"), store_->new_job_id_for("ann", "r1"));
  EXPECT_NE(store_->new_job_id_for("ann", "r1"), store_->new_job_id_for("bob", "r1"));
  EXPECT_NE(store_->new_job_id_for("ann", ""), store_->new_job_id_for("ann", ""));
  EXPECT_TRUE(server::is_job_id(store_->new_job_id_for("ann", "r1")));

  const std::string id = accept("ann", "r1");
  auto prior = store_->find_request("ann", "r1");
  ASSERT_TRUE(prior.has_value());
  EXPECT_EQ(prior->job_id, id);
  EXPECT_EQ(prior->sha256, "digest of volume bytes");
  EXPECT_FALSE(store_->find_request("bob", "r1").has_value());
  // A second frontend that received the same request at once: its upload
  // goes, the job stays as the first one made it.
  ClusterJobStore other(*connection_, *files_, 8, absl::Hours(1));
  const std::string upload = other.upload_path(id, ".nii.gz");
  std::ofstream(upload) << "volume bytes";
  v1::JobRecord again;
  again.mutable_job()->set_job_id(id);
  ASSERT_THAT(other.accept(again, upload), testing::IsOk());
  EXPECT_FALSE(fs::exists(upload));
  EXPECT_EQ(other.get(id).value().owner(), "ann");
  EXPECT_EQ(connection_->queue->stored().value(), 1u);
  EXPECT_TRUE(fs::is_regular_file(job_dir(id) / "input.nii.gz"));
  EXPECT_TRUE(fs::is_regular_file(job_dir(id) / "job.pb"));
}

TEST_F(ClusterRolesTest, AnEndedJobWhoseEndWasNotLoggedIsToldByItsRecord) {
  const std::string id = accept("ann", "");
  finish(id, v1::JOB_STATE_SUCCEEDED);
  RecordingListener logged;
  ASSERT_THAT(store_->listen(id, 0, &logged), testing::IsOk());
  ASSERT_TRUE(logged.ended());
  std::vector<std::string> kinds;
  for (const auto& event : logged.events()) kinds.push_back(event.has_finished() ? "f" : "-");
  EXPECT_EQ(kinds, (std::vector<std::string>{"-", "-", "f"}));  // queued, started, finished

  // The worker died between the record and the event; or the events aged out.
  ASSERT_THAT(connection_->events->remove(id), testing::IsOk());
  RecordingListener unlogged;
  ASSERT_THAT(store_->listen(id, 0, &unlogged), testing::IsOk());
  ASSERT_TRUE(unlogged.ended());
  ASSERT_EQ(unlogged.events().size(), 1u);
  EXPECT_TRUE(unlogged.events()[0].has_finished());
}

TEST_F(ClusterRolesTest, ALiveJobIsFollowedUntilItsEnd) {
  const std::string id = accept("ann", "");
  RecordingListener listener;
  ASSERT_THAT(store_->listen(id, 0, &listener), testing::IsOk());
  auto claim = connection_->jobs->claim(id).value();
  v1::JobEvent stage;
  stage.mutable_stage_started()->set_stage("surface");
  ASSERT_THAT(connection_->jobs->publish(claim, stage), testing::IsOk());
  // GetJob reads a running job's stage from its newest event.
  bool staged = false;
  for (int i = 0; i < 100 && !staged; ++i) {
    staged = store_->get(id).value().stage() == "surface";
    if (!staged) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(staged);
  ASSERT_THAT(connection_->jobs->finish(claim, v1::JOB_STATE_FAILED, {}), testing::IsOk());
  for (int i = 0; i < 250 && !listener.ended(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  store_->unlisten(id, &listener);
  const auto events = listener.events();
  ASSERT_EQ(events.size(), 4u);  // queued, started, stage, failed
  EXPECT_TRUE(events[2].has_stage_started());
  EXPECT_TRUE(events[3].has_failed());
  for (size_t i = 1; i < events.size(); ++i)
    EXPECT_GT(events[i].sequence(), events[i - 1].sequence());
}

TEST_F(ClusterRolesTest, DeletesTakeQueuedJobsAtOnceAndRunningOnesWhenTheyStop) {
  const std::string queued = accept("ann", "");
  EXPECT_EQ(store_->remove(queued).value(), v1::JOB_STATE_QUEUED);
  EXPECT_EQ(store_->get(queued).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(connection_->jobs->get(queued).status().code(), absl::StatusCode::kNotFound);
  EXPECT_FALSE(fs::exists(job_dir(queued)));

  const std::string running = accept("ann", "");
  auto claim = connection_->jobs->claim(running).value();
  EXPECT_EQ(store_->remove(running).value(), v1::JOB_STATE_RUNNING);
  EXPECT_EQ(store_->get(running).status().code(), absl::StatusCode::kNotFound);
  const v1::JobRecord marked = connection_->jobs->get(running).value();
  EXPECT_TRUE(marked.deleted());
  EXPECT_TRUE(marked.cancel_requested());
  EXPECT_TRUE(fs::exists(job_dir(running)));  // its worker still writes there
  EXPECT_EQ(store_->list({}).value().jobs.size(), 0u);
}

TEST_F(ClusterRolesTest, ExpiryRemovesEndedJobsWithTheirFilesAndKeepsTheRest) {
  const std::string ended = accept("ann", "");
  finish(ended, v1::JOB_STATE_SUCCEEDED);
  const std::string queued = accept("ann", "");
  EXPECT_TRUE(store_->expire(absl::Hours(1), 100).empty());
  const auto removed = store_->expire(absl::ZeroDuration(), 100);
  EXPECT_EQ(removed, std::vector<std::string>{ended});
  EXPECT_FALSE(fs::exists(job_dir(ended)));
  EXPECT_EQ(connection_->jobs->get(ended).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->get(queued).value().state(), v1::JOB_STATE_QUEUED);

  // An upload a dead frontend left behind goes too, once old enough.
  const std::string abandoned = store_->upload_path(queued, ".nrrd");
  std::ofstream(abandoned) << "half an upload";
  EXPECT_EQ(store_->remove_abandoned_uploads(absl::Hours(1)), 0u);
  fs::last_write_time(abandoned, fs::file_time_type::clock::now() - std::chrono::hours(2));
  EXPECT_EQ(store_->remove_abandoned_uploads(absl::Hours(1)), 1u);
  EXPECT_FALSE(fs::exists(abandoned));
}

TEST_F(ClusterRolesTest, ARequestIdReusedAfterADeleteIsANewJobAndTheOldMessageIsDropped) {
  const std::string first = accept("ann", "r1");
  ASSERT_THAT(store_->remove(first), testing::IsOk());
  std::this_thread::sleep_for(std::chrono::milliseconds(2));  // another creation time
  const std::string second = accept("ann", "r1");
  ASSERT_EQ(second, first);  // the same id, made again
  EXPECT_EQ(connection_->queue->stored().value(), 2u);
  // The deleted job's message comes first and must not start the new job.
  auto old_message = connection_->queue->take(absl::Seconds(2)).value();
  ASSERT_TRUE(old_message.has_value());
  EXPECT_EQ(connection_->jobs->claim(first, {old_message->made()}).status().code(),
            absl::StatusCode::kFailedPrecondition);
  ASSERT_THAT(old_message->ack(), testing::IsOk());
  auto new_message = connection_->queue->take(absl::Seconds(2)).value();
  ASSERT_TRUE(new_message.has_value());
  auto claim = connection_->jobs->claim(second, {new_message->made()});
  ASSERT_THAT(claim, testing::IsOk());
  EXPECT_EQ(claim->attempt, 1u);
}

TEST_F(ClusterRolesTest, ShutdownEndsEveryFollowAndListenRefusesAfter) {
  const std::string id = accept("ann", "");
  RecordingListener listener;
  ASSERT_THAT(store_->listen(id, 0, &listener), testing::IsOk());
  store_->close();
  EXPECT_TRUE(listener.ended());
  store_->unlisten(id, &listener);  // gone already: returns at once
  RecordingListener late;
  EXPECT_EQ(store_->listen(id, 0, &late).code(), absl::StatusCode::kUnavailable);
}

TEST_F(ClusterRolesTest, FollowsOfDeletedOrSilentlyEndedJobsAreEnded) {
  const std::string deleted = accept("ann", "");
  RecordingListener of_deleted;
  ASSERT_THAT(store_->listen(deleted, 0, &of_deleted), testing::IsOk());
  ASSERT_THAT(store_->remove(deleted), testing::IsOk());
  store_->check_follows();
  EXPECT_TRUE(of_deleted.ended());

  // A job whose record ended with no end event (its worker died between
  // the two): the record stands in once the event is overdue.
  const std::string silent = accept("ann", "");
  RecordingListener of_silent;
  ASSERT_THAT(store_->listen(silent, 0, &of_silent), testing::IsOk());
  auto stored = connection_->states->get(silent).value();
  v1::JobRecord record;
  ASSERT_TRUE(record.ParseFromString(stored.value));
  record.mutable_job()->set_state(v1::JOB_STATE_FAILED);
  ASSERT_TRUE(
      connection_->states->update(silent, record.SerializeAsString(), stored.revision).ok());
  store_->check_follows();
  EXPECT_FALSE(of_silent.ended());  // the event may still come
  std::this_thread::sleep_for(std::chrono::milliseconds(5200));
  store_->check_follows();
  ASSERT_TRUE(of_silent.ended());
  EXPECT_TRUE(of_silent.events().back().has_failed());
  store_->unlisten(deleted, &of_deleted);
  store_->unlisten(silent, &of_silent);
}

TEST_F(ClusterRolesTest, AJobWhoseLastDeliveryDiedIsFailedPastTheTimeout) {
  ClusterJobStore impatient(*connection_, *files_, 8, absl::ZeroDuration());
  // Not on the final delivery: another comes, however long it waits.
  const std::string waiting = accept("ann", "");
  (void)connection_->jobs->claim(waiting, {"", 1, false}).value();
  // On the final delivery: its worker then dies for good.
  const std::string lost = accept("ann", "");
  (void)connection_->jobs->claim(lost, {"", 2, true}).value();
  EXPECT_TRUE(store_->expire(absl::Hours(1), 100).empty());
  EXPECT_EQ(store_->get(lost).value().state(), v1::JOB_STATE_RUNNING);
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  (void)impatient.expire(absl::Hours(1), 100);
  const v1::Job job = store_->get(lost).value();
  EXPECT_EQ(job.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(job.error().code(), static_cast<int>(absl::StatusCode::kDeadlineExceeded));
  EXPECT_EQ(store_->get(waiting).value().state(), v1::JOB_STATE_RUNNING);
}

TEST_F(ClusterRolesTest, AnotherMessageNeverTakesARunningJobOver) {
  const std::string id = accept("ann", "");
  auto first = connection_->jobs->claim(id, {"", 10, false});
  ASSERT_THAT(first, testing::IsOk());
  // The same message again (its worker went silent) takes over...
  auto again = connection_->jobs->claim(id, {"", 10, false});
  ASSERT_THAT(again, testing::IsOk());
  EXPECT_EQ(again->attempt, 2u);
  // ...a second message of the job (a give-back whose ack was lost) does not.
  EXPECT_EQ(connection_->jobs->claim(id, {"", 11, false}).status().code(),
            absl::StatusCode::kFailedPrecondition);
  // A give-back makes the job QUEUED, and the new message takes it.
  ASSERT_THAT(connection_->jobs->requeue(*again), testing::IsOk());
  EXPECT_EQ(store_->get(id).value().state(), v1::JOB_STATE_QUEUED);
  EXPECT_EQ(connection_->jobs->requeue(*again).code(), absl::StatusCode::kAborted);
  auto third = connection_->jobs->claim(id, {"", 12, false});
  ASSERT_THAT(third, testing::IsOk());
  EXPECT_EQ(third->attempt, 3u);
}

// grpc.health.v1 on a server: `service` "" is the overall health.
grpc::health::v1::HealthCheckResponse::ServingStatus health(int port, const std::string& service) {
  auto channel =
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse reply;
  if (!grpc::health::v1::Health::NewStub(channel)->Check(&context, request, &reply).ok())
    return grpc::health::v1::HealthCheckResponse::UNKNOWN;
  return reply.status();
}

server::ServerConfig role_config(const fs::path& dir, const std::string& role,
                                 const std::string& nats_url) {
  server::ServerConfig config;
  config.role = role;
  config.nats_url = nats_url;
  config.artifact_dir = (dir / "artifacts").string();
  config.spool_dir = (dir / ("spool-" + role)).string();
  config.listen = "127.0.0.1:0";
  config.workers = 1;
  config.spool_reserve_bytes = 1 << 20;
  config.worker_executable = LABELMESH_WORKER;
  return config;
}

TEST_F(ClusterRolesTest, AFrontendIsReadyWhileItReachesNatsAndLiveThroughout) {
  using Status = grpc::health::v1::HealthCheckResponse;
  auto frontend = server::LabelmeshServer::start(role_config(dir_, "frontend", nats_->url()));
  ASSERT_THAT(frontend, testing::IsOk());
  const int port = (*frontend)->port();
  EXPECT_EQ(health(port, ""), Status::SERVING);
  EXPECT_EQ(health(port, server::kLivenessService), Status::SERVING);

  nats_->stop();
  auto wait_for = [&](Status::ServingStatus wanted) {
    for (int i = 0; i < 150 && health(port, "") != wanted; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return health(port, "");
  };
  EXPECT_EQ(wait_for(Status::NOT_SERVING), Status::NOT_SERVING);
  EXPECT_EQ(health(port, server::kLivenessService), Status::SERVING);
  nats_->restart();
  EXPECT_EQ(wait_for(Status::SERVING), Status::SERVING);
  (*frontend)->shutdown();
}

// A frontend cut off from NATS refuses a Submit at once as UNAVAILABLE (what
// `labelmesh submit` retries), before taking the upload; once NATS is back
// the same Submit is accepted.
TEST_F(ClusterRolesTest, ASubmitWhileNatsIsDownIsUnavailableAtOnce) {
  using Status = grpc::health::v1::HealthCheckResponse;
  testing::ServiceHarness frontend(role_config(dir_, "frontend", nats_->url()));
  const int port = frontend.server().port();
  const fs::path volume = testing::write_phantom(dir_, volume::PhantomShape::kSphere);
  auto wait_for = [&](Status::ServingStatus wanted) {
    for (int i = 0; i < 150 && health(port, "") != wanted; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return health(port, "");
  };
  nats_->stop();
  ASSERT_EQ(wait_for(Status::NOT_SERVING), Status::NOT_SERVING);
  v1::SubmitReply reply;
  const auto start = std::chrono::steady_clock::now();
  const grpc::Status refused = frontend.submit(volume, {}, &reply);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAVAILABLE) << refused.error_message();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
  EXPECT_NE(refused.error_message().find("NATS"), std::string::npos) << refused.error_message();
  nats_->restart();
  ASSERT_EQ(wait_for(Status::SERVING), Status::SERVING);
  const grpc::Status accepted = frontend.submit(volume, {}, &reply);
  EXPECT_TRUE(accepted.ok()) << accepted.error_message();
  EXPECT_FALSE(reply.job_id().empty());
  frontend.shutdown();
}

TEST_F(ClusterRolesTest, AWorkerRunsAJobFromTheSharedDirectoryAndServesOnlyHealth) {
  const std::string id = accept_sphere();
  auto worker = server::LabelmeshServer::start(role_config(dir_, "worker", nats_->url()));
  ASSERT_THAT(worker, testing::IsOk());
  const v1::Job job = wait_until_ended(id);
  ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  EXPECT_EQ(job.attempts(), 1u);
  const auto artifacts = store_->artifacts(id).value();
  ASSERT_FALSE(artifacts.empty());
  for (const auto& artifact : artifacts) {
    EXPECT_EQ(fs::file_size(store_->artifact_path(job, artifact.name())), artifact.size_bytes())
        << artifact.name();
  }
  // The job counted where the worker's metrics are served; its input gone.
  const std::string metrics = (*worker)->metrics().text();
  EXPECT_NE(metrics.find("labelmesh_jobs_total{outcome=\"succeeded\"} 1"), std::string::npos);
  EXPECT_NE(metrics.find("labelmesh_stage_duration_seconds_count"), std::string::npos);
  // The worker cleans up just after it records the end.
  for (int i = 0; i < 100 && fs::exists(job_dir(id) / "input.nii.gz"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(fs::exists(job_dir(id) / "input.nii.gz"));

  EXPECT_EQ(health((*worker)->port(), ""), grpc::health::v1::HealthCheckResponse::SERVING);
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string((*worker)->port()),
                                     grpc::InsecureChannelCredentials());
  grpc::ClientContext context;
  v1::Job reply;
  v1::GetJobRequest request;
  request.set_job_id(id);
  EXPECT_EQ(v1::MeshingService::NewStub(channel)->GetJob(&context, request, &reply).error_code(),
            grpc::StatusCode::UNIMPLEMENTED);
  (*worker)->shutdown();
}

TEST_F(ClusterRolesTest, AWorkerWithNoRoomForResultsLeavesJobsQueued) {
  const std::string id = accept_sphere();

  auto full_config = role_config(dir_, "worker", nats_->url());
  full_config.spool_reserve_bytes = uint64_t{1} << 60;  // More than any disk has free.
  auto full = server::LabelmeshServer::start(full_config);
  ASSERT_THAT(full, testing::IsOk());
  std::this_thread::sleep_for(std::chrono::seconds(3));
  v1::Job job = store_->get(id).value();
  EXPECT_EQ(job.state(), v1::JOB_STATE_QUEUED) << job.error().message();
  EXPECT_EQ(job.attempts(), 0u);
  (*full)->shutdown();

  auto worker = server::LabelmeshServer::start(role_config(dir_, "worker", nats_->url()));
  ASSERT_THAT(worker, testing::IsOk());
  job = wait_until_ended(id);
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error().message();
  EXPECT_EQ(job.attempts(), 1u);
  (*worker)->shutdown();
}

TEST(ClusterRoleConfig, FrontendsAndWorkersNeedNatsAndTheSharedDirectory) {
  server::ServerConfig config;
  config.role = "frontend";
  EXPECT_NE(server::validate_config(config).message().find("--nats-url"), std::string::npos);
  config.nats_url = "nats://127.0.0.1:4222";
  EXPECT_NE(server::validate_config(config).message().find("--artifact-dir"), std::string::npos);
  config.artifact_dir = "/shared";
  EXPECT_THAT(server::validate_config(config), testing::IsOk());
  config.role = "worker";
  config.workers = 0;
  EXPECT_NE(server::validate_config(config).message().find("--workers"), std::string::npos);
  config.role = "scheduler";
  EXPECT_NE(server::validate_config(config).message().find("--role"), std::string::npos);
}

}  // namespace
}  // namespace labelmesh
