// SPDX-License-Identifier: AGPL-3.0-or-later
// The job queue and job states on a real nats-server with JetStream.
#include "server/cluster/job_queue.h"

#include <gtest/gtest.h>

#include <set>

#include "cluster/nats_server.h"
#include "server/cluster/job_states.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::cluster {
namespace {

struct Cluster {
  explicit Cluster(const std::string& name) : server(testing::scratch_dir(name)) {}

  std::unique_ptr<NatsClient> client() {
    auto client = NatsClient::connect(server.url(), "labelmesh-test", absl::Seconds(5));
    EXPECT_THAT(client, testing::IsOk());
    return client.ok() ? std::move(*client) : nullptr;
  }

  testing::NatsServer server;
};

JobQueueConfig quick(absl::Duration ack_wait = absl::Seconds(30), int max_deliver = 3) {
  JobQueueConfig config;
  config.ack_wait = ack_wait;
  config.max_deliver = max_deliver;
  return config;
}

std::unique_ptr<JobQueue> open_queue(NatsClient& client, const JobQueueConfig& config) {
  auto queue = JobQueue::open(client, config);
  EXPECT_THAT(queue, testing::IsOk());
  return queue.ok() ? std::move(*queue) : nullptr;
}

TEST(JobQueue, ADuplicateSubmitIsQueuedOnceAndEachJobGoesToOneWorker) {
  Cluster cluster("duplicates");
  ASSERT_TRUE(cluster.server.running());
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  auto queue = open_queue(*client, quick());
  ASSERT_NE(queue, nullptr);
  EXPECT_EQ(queue->enqueue("job-a").value(), true);
  EXPECT_EQ(queue->enqueue("job-a").value(), false);
  EXPECT_EQ(queue->enqueue("job-b").value(), true);
  EXPECT_EQ(queue->stored().value(), 2u);

  // A second worker's connection shares the same consumer.
  auto other_client = cluster.client();
  auto other = open_queue(*other_client, quick());
  ASSERT_NE(other, nullptr);
  auto first = queue->take(absl::Seconds(2));
  auto second = other->take(absl::Seconds(2));
  ASSERT_THAT(first, testing::IsOk());
  ASSERT_THAT(second, testing::IsOk());
  ASSERT_TRUE(first->has_value() && second->has_value());
  EXPECT_EQ((std::set<std::string>{(*first)->job_id(), (*second)->job_id()}),
            (std::set<std::string>{"job-a", "job-b"}));
  EXPECT_EQ((*first)->delivered(), 1u);
  EXPECT_THAT((*first)->ack(), testing::IsOk());
  EXPECT_THAT((*second)->ack(), testing::IsOk());
  EXPECT_FALSE(queue->take(absl::Milliseconds(300)).value().has_value());
  EXPECT_EQ(queue->stored().value(), 0u);  // acknowledged jobs leave the stream
}

TEST(JobQueue, AJobWhoseWorkerDiedGoesToTheNextWorker) {
  Cluster cluster("redelivery");
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  const auto config = quick(absl::Seconds(1));
  auto queue = open_queue(*client, config);
  ASSERT_NE(queue, nullptr);
  ASSERT_THAT(queue->enqueue("job-a"), testing::IsOk());
  {
    // A worker takes the job and dies without a word: its connection ends.
    auto doomed_client = cluster.client();
    auto doomed = open_queue(*doomed_client, config);
    auto taken = doomed->take(absl::Seconds(2));
    ASSERT_TRUE(taken.ok() && taken->has_value());
    EXPECT_EQ((*taken)->delivered(), 1u);
  }
  auto again = queue->take(absl::Seconds(5));
  ASSERT_TRUE(again.ok() && again->has_value());
  EXPECT_EQ((*again)->job_id(), "job-a");
  EXPECT_EQ((*again)->delivered(), 2u);
  EXPECT_THAT((*again)->ack(), testing::IsOk());
}

TEST(JobQueue, AWorkerThatSaysItIsWorkingKeepsItsJob) {
  Cluster cluster("in-progress");
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  const auto config = quick(absl::Seconds(2));
  auto queue = open_queue(*client, config);
  ASSERT_THAT(queue->enqueue("job-a"), testing::IsOk());
  auto taken = queue->take(absl::Seconds(2));
  ASSERT_TRUE(taken.ok() && taken->has_value());
  auto other_client = cluster.client();
  auto other = open_queue(*other_client, config);
  // Two ack waits, the job reported in progress every quarter wait: nobody
  // else gets it.
  for (int i = 0; i < 8; ++i) {
    EXPECT_THAT((*taken)->in_progress(), testing::IsOk());
    auto stolen = other->take(absl::Milliseconds(500));
    ASSERT_THAT(stolen, testing::IsOk());
    EXPECT_FALSE(stolen->has_value()) << "handed out again after " << i << " quarter waits";
  }
  EXPECT_THAT((*taken)->ack(), testing::IsOk());
}

TEST(JobQueue, APoisonJobStopsAfterMaxDeliveries) {
  Cluster cluster("max-deliver");
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  auto queue = open_queue(*client, quick(absl::Seconds(30), 2));
  ASSERT_THAT(queue->enqueue("poison"), testing::IsOk());
  for (uint64_t attempt = 1; attempt <= 2; ++attempt) {
    auto taken = queue->take(absl::Seconds(2));
    ASSERT_TRUE(taken.ok() && taken->has_value());
    EXPECT_EQ((*taken)->delivered(), attempt);
    EXPECT_THAT((*taken)->nak(), testing::IsOk());
  }
  EXPECT_FALSE(queue->take(absl::Milliseconds(500)).value().has_value());
}

TEST(JobQueue, QueuedJobsOutliveANatsRestart) {
  Cluster cluster("restart");
  {
    auto client = cluster.client();
    auto queue = open_queue(*client, quick());
    for (const char* id : {"job-a", "job-b", "job-c"}) ASSERT_TRUE(queue->enqueue(id).ok());
  }
  cluster.server.restart();
  ASSERT_TRUE(cluster.server.running());
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  auto queue = open_queue(*client, quick());
  ASSERT_NE(queue, nullptr);
  std::set<std::string> taken;
  for (int i = 0; i < 3; ++i) {
    auto job = queue->take(absl::Seconds(2));
    ASSERT_TRUE(job.ok() && job->has_value());
    taken.insert((*job)->job_id());
    EXPECT_THAT((*job)->ack(), testing::IsOk());
  }
  EXPECT_EQ(taken, (std::set<std::string>{"job-a", "job-b", "job-c"}));
}

TEST(JobStates, AStaleWriterIsRefused) {
  Cluster cluster("states");
  auto client = cluster.client();
  ASSERT_NE(client, nullptr);
  auto states = JobStates::open(*client, "labelmesh_jobs");
  ASSERT_THAT(states, testing::IsOk());
  auto& table = **states;
  const auto created = table.create("job-a", "queued");
  ASSERT_THAT(created, testing::IsOk());
  EXPECT_EQ(table.create("job-a", "queued").status().code(), absl::StatusCode::kAlreadyExists);

  // Two workers read the same revision; the first to write wins.
  const auto seen = table.get("job-a").value();
  EXPECT_EQ(seen.value, "queued");
  EXPECT_EQ(seen.revision, *created);
  const auto running = table.update("job-a", "running on worker 2", seen.revision);
  ASSERT_THAT(running, testing::IsOk());
  const auto stale = table.update("job-a", "finished by worker 1", seen.revision);
  EXPECT_THAT(stale, testing::StatusIs(absl::StatusCode::kAborted)) << stale.status();
  EXPECT_EQ(table.get("job-a").value().value, "running on worker 2");

  EXPECT_THAT(table.remove("job-a"), testing::IsOk());
  EXPECT_EQ(table.get("job-a").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(table.get("never").status().code(), absl::StatusCode::kNotFound);
}

TEST(NatsClient, NoServerIsUnavailable) {
  testing::NatsServer server(testing::scratch_dir("gone"));
  const std::string url = server.url();
  server.stop();
  auto client = NatsClient::connect(url, "labelmesh-test", absl::Milliseconds(500));
  EXPECT_THAT(client, testing::StatusIs(absl::StatusCode::kUnavailable)) << client.status();
}

// An unanswered call (NATS away, the client reconnecting) is UNAVAILABLE, what
// clients retry, not DEADLINE_EXCEEDED, which is for their own deadlines.
TEST(NatsClient, AnUnansweredCallIsUnavailable) {
  const absl::Status status = nats_error(NATS_TIMEOUT, "publish job-x");
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_NE(std::string(status.message()).find("publish job-x"), std::string::npos) << status;
  EXPECT_EQ(nats_error(NATS_NOT_FOUND, "get").code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(nats_error(NATS_OK, "get"), testing::IsOk());
}

}  // namespace
}  // namespace labelmesh::cluster
