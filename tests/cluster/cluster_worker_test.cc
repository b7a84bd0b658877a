// SPDX-License-Identifier: AGPL-3.0-or-later
// The worker loop on a real nats-server, with runs that take longer than
// the queue's ack wait, fail, or are cancelled.
#include "server/cluster/cluster_worker.h"

#include <gtest/gtest.h>

#include <thread>

#include "cluster/cluster_node.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::cluster {
namespace {

// Short, yet twice any pause between heartbeats on a loaded machine.
struct Node : testing::ClusterNode {
  explicit Node(const testing::NatsServer& server) : ClusterNode(server, absl::Seconds(2)) {}
};

using testing::new_job;

constexpr ClusterWorkerConfig kQuick{absl::Seconds(1), absl::Milliseconds(250)};

TEST(ClusterWorker, ARunLongerThanTheAckWaitStaysWithItsWorker) {
  testing::NatsServer server(testing::scratch_dir("long-run"));
  Node frontend(server), worker_node(server), idle_node(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("long")), testing::IsOk());
  std::atomic<int> runs = 0;
  // While the job runs, another worker polls the same queue and must get
  // nothing.
  std::atomic<bool> stolen = false;
  std::thread idle;
  ClusterWorker worker(
      *worker_node.queue, *worker_node.jobs,
      [&](const v1::JobRecord&, const Claim& claim, const std::atomic<bool>&) {
        ++runs;
        idle = std::thread([&] {
          for (int i = 0; i < 10; ++i) {
            auto taken = idle_node.queue->take(absl::Milliseconds(400));
            if (taken.ok() && taken->has_value()) stolen = true;
          }
        });
        std::this_thread::sleep_for(std::chrono::milliseconds(4500));  // 2.25 ack waits
        JobOutcome outcome{v1::JOB_STATE_SUCCEEDED, {}};
        outcome.result.add_artifacts()->set_name("attempt-" + std::to_string(claim.attempt));
        return outcome;
      },
      kQuick);
  EXPECT_EQ(worker.run_one().value(), true);
  if (idle.joinable()) idle.join();
  EXPECT_FALSE(stolen);
  EXPECT_EQ(runs, 1);
  const auto record = frontend.jobs->get("long").value();
  EXPECT_EQ(record.job().state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(record.job().attempts(), 1u);
  ASSERT_EQ(record.artifacts_size(), 1);
  EXPECT_EQ(record.artifacts(0).name(), "attempt-1");
  EXPECT_EQ(frontend.queue->stored().value(), 0u);
  EXPECT_EQ(worker.run_one().value(), false);  // nothing left
}

TEST(ClusterWorker, ACancelReachesTheRunOnItsMachine) {
  testing::NatsServer server(testing::scratch_dir("cancel-run"));
  Node frontend(server), worker_node(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("doomed")), testing::IsOk());
  ClusterWorker worker(
      *worker_node.queue, *worker_node.jobs,
      [&](const v1::JobRecord&, const Claim&, const std::atomic<bool>& cancelled) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (!cancelled && std::chrono::steady_clock::now() < deadline)
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        return JobOutcome{cancelled ? v1::JOB_STATE_CANCELLED : v1::JOB_STATE_SUCCEEDED, {}};
      },
      kQuick);
  std::thread client([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_THAT(frontend.jobs->cancel("doomed"), testing::IsOk());
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(worker.run_one().value(), true);
  client.join();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_EQ(frontend.jobs->get("doomed").value().job().state(), v1::JOB_STATE_CANCELLED);
}

TEST(ClusterWorker, AFailedRunEndsTheJobFailedAndARetriedSubmitDoesNotRunItAgain) {
  testing::NatsServer server(testing::scratch_dir("failed-run"));
  Node frontend(server), worker_node(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("bad")), testing::IsOk());
  int runs = 0;
  ClusterWorker worker(
      *worker_node.queue, *worker_node.jobs,
      [&](const v1::JobRecord&, const Claim&, const std::atomic<bool>&) {
        ++runs;
        JobOutcome outcome{v1::JOB_STATE_FAILED, {}};
        outcome.result.mutable_job()->mutable_error()->set_message("unreadable volume");
        return outcome;
      },
      kQuick);
  EXPECT_EQ(worker.run_one().value(), true);
  const auto record = frontend.jobs->get("bad").value();
  EXPECT_EQ(record.job().state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(record.job().error().message(), "unreadable volume");
  // The same id submitted again is the same ended job, and the queue's
  // duplicate window keeps it from being queued again.
  const auto again = frontend.jobs->submit(new_job("bad"));
  ASSERT_THAT(again, testing::IsOk());
  EXPECT_EQ(again->job().state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(worker.run_one().value(), false);
  EXPECT_EQ(runs, 1);
  EXPECT_EQ(frontend.queue->stored().value(), 0u);
}

TEST(ClusterWorker, AJobGivenBackAtShutdownIsNotCountedAsAFailedDelivery) {
  testing::NatsServer server(testing::scratch_dir("give-back"));
  Node frontend(server), worker_node(server);
  ASSERT_THAT(frontend.jobs->submit(new_job("interrupted")), testing::IsOk());
  // The queue stops a job after max_deliver (3) deliveries: four stops in a
  // row must not lose it.
  auto stop = [](const v1::JobRecord&, const Claim&, const std::atomic<bool>&) {
    return JobOutcome{v1::JOB_STATE_QUEUED, {}};
  };
  for (int i = 0; i < 4; ++i) {
    ClusterWorker stopping(*worker_node.queue, *worker_node.jobs, stop, kQuick);
    ASSERT_EQ(stopping.run_one().value(), true) << "stop " << i;
  }
  uint64_t delivered = 0;
  ClusterWorker worker(
      *worker_node.queue, *worker_node.jobs,
      [&](const v1::JobRecord&, const Claim& claim, const std::atomic<bool>&) {
        delivered = claim.attempt;
        return JobOutcome{v1::JOB_STATE_SUCCEEDED, {}};
      },
      kQuick);
  ASSERT_EQ(worker.run_one().value(), true);
  EXPECT_EQ(delivered, 5u);  // the fifth attempt, on a fresh message
  EXPECT_EQ(frontend.jobs->get("interrupted").value().job().state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(frontend.queue->stored().value(), 0u);
}

}  // namespace
}  // namespace labelmesh::cluster
