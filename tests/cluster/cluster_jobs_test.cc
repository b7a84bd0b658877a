// SPDX-License-Identifier: AGPL-3.0-or-later
// A job's life across machines on a real nats-server: retried submits,
// a worker that dies mid-job, a late result refused, cancellation.
#include "server/cluster/cluster_jobs.h"

#include <gtest/gtest.h>

#include "cluster/cluster_node.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::cluster {
namespace {

// A silent worker loses its job within a second.
struct Node : testing::ClusterNode {
  explicit Node(const testing::NatsServer& server) : ClusterNode(server, absl::Seconds(1)) {}
};

using testing::new_job;

// The job's logged events, by kind.
std::vector<v1::JobEvent::EventCase> logged(EventLog& events, const std::string& job_id) {
  std::vector<v1::JobEvent::EventCase> kinds;
  auto follower = events.follow(job_id, 0);
  EXPECT_THAT(follower, testing::IsOk());
  while (true) {
    auto next = (*follower)->next(absl::Milliseconds(300));
    if (!next.ok() || !next->has_value()) break;
    v1::JobEvent event;
    EXPECT_TRUE(event.ParseFromString((*next)->data));
    kinds.push_back(event.event_case());
  }
  return kinds;
}

TEST(ClusterJobs, ARetriedSubmitGivesTheSameJobQueuedOnce) {
  testing::NatsServer server(testing::scratch_dir("submit"));
  Node frontend(server), other_frontend(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("j1")), testing::IsOk());
  auto again = other_frontend.jobs->submit(new_job("j1"));
  ASSERT_THAT(again, testing::IsOk());
  EXPECT_EQ(again->job().state(), v1::JOB_STATE_QUEUED);
  EXPECT_EQ(frontend.queue->stored().value(), 1u);
}

TEST(ClusterJobs, ALateResultFromAWorkerThatLostItsJobIsRefused) {
  testing::NatsServer server(testing::scratch_dir("fencing"));
  Node frontend(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("j1")), testing::IsOk());

  // Worker A takes the job and falls silent; the queue hands it to B.
  Node a(server), b(server);
  auto first = a.queue->take(absl::Seconds(2));
  ASSERT_TRUE(first.ok() && first->has_value());
  auto a_claim = a.jobs->claim("j1");
  ASSERT_THAT(a_claim, testing::IsOk());
  EXPECT_EQ(a_claim->attempt, 1u);
  auto second = b.queue->take(absl::Seconds(5));
  ASSERT_TRUE(second.ok() && second->has_value());
  EXPECT_EQ((*second)->delivered(), 2u);
  auto b_claim = b.jobs->claim("j1");
  ASSERT_THAT(b_claim, testing::IsOk());
  EXPECT_EQ(b_claim->attempt, 2u);

  v1::JobRecord result;
  result.add_artifacts()->set_name("volume.vtu");
  EXPECT_THAT(b.jobs->finish(*b_claim, v1::JOB_STATE_SUCCEEDED, result), testing::IsOk());
  EXPECT_THAT((*second)->ack(), testing::IsOk());
  // A comes back late: its result is refused and the job stays B's.
  const auto late = a.jobs->finish(*a_claim, v1::JOB_STATE_FAILED, {});
  EXPECT_THAT(late, testing::StatusIs(absl::StatusCode::kAborted)) << late.status();
  const auto job = frontend.jobs->get("j1").value();
  EXPECT_EQ(job.job().state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(job.job().attempts(), 2u);
  ASSERT_EQ(job.artifacts_size(), 1);
  // A delivery of an ended job is not run again.
  EXPECT_EQ(a.jobs->claim("j1").status().code(), absl::StatusCode::kFailedPrecondition);
  // Exactly one end: queued, two starts, one finish.
  using E = v1::JobEvent;
  EXPECT_EQ(logged(*frontend.events, "j1"),
            (std::vector<E::EventCase>{E::kQueued, E::kStarted, E::kStarted, E::kFinished}));
}

TEST(ClusterJobs, CancelEndsAQueuedJobAndAsksARunningOneToStop) {
  testing::NatsServer server(testing::scratch_dir("cancel"));
  Node frontend(server), worker(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("queued")), testing::IsOk());
  ASSERT_THAT(frontend.jobs->submit(new_job("running")), testing::IsOk());
  auto claim = worker.jobs->claim("running");
  ASSERT_THAT(claim, testing::IsOk());

  EXPECT_EQ(frontend.jobs->cancel("queued").value().job().state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(worker.jobs->claim("queued").status().code(), absl::StatusCode::kFailedPrecondition);

  const auto asked = frontend.jobs->cancel("running");
  ASSERT_THAT(asked, testing::IsOk());
  EXPECT_EQ(asked->job().state(), v1::JOB_STATE_RUNNING);
  EXPECT_TRUE(worker.jobs->get("running").value().cancel_requested());
  EXPECT_EQ(worker.jobs->finish(*claim, v1::JOB_STATE_CANCELLED, {}).value().job().state(),
            v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(frontend.jobs->cancel("running").status().code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(frontend.jobs->cancel("unknown").status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace labelmesh::cluster
