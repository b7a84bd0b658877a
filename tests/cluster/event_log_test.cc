// SPDX-License-Identifier: AGPL-3.0-or-later
// Job events on a real nats-server: followed from any connection and any
// point, and kept across a restart.
#include "server/cluster/event_log.h"

#include <gtest/gtest.h>

#include "cluster/nats_server.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::cluster {
namespace {

std::unique_ptr<NatsClient> connect(const testing::NatsServer& server) {
  auto client = NatsClient::connect(server.url(), "labelmesh-test", absl::Seconds(5));
  EXPECT_THAT(client, testing::IsOk());
  return client.ok() ? std::move(*client) : nullptr;
}

std::unique_ptr<EventLog> open_log(NatsClient& client) {
  auto log = EventLog::open(client, {});
  EXPECT_THAT(log, testing::IsOk());
  return log.ok() ? std::move(*log) : nullptr;
}

// The data of the events `follower` gives within `wait` each.
std::vector<std::string> drain(EventFollower& follower, absl::Duration wait) {
  std::vector<std::string> data;
  while (true) {
    auto event = follower.next(wait);
    if (!event.ok() || !event->has_value()) break;
    data.push_back((*event)->data);
  }
  return data;
}

TEST(EventLog, AnotherFrontendFollowsAJobFromAnyPoint) {
  testing::NatsServer server(testing::scratch_dir("follow"));
  ASSERT_TRUE(server.running());
  auto worker_client = connect(server);
  auto frontend_client = connect(server);
  ASSERT_TRUE(worker_client && frontend_client);
  auto worker = open_log(*worker_client);
  auto frontend = open_log(*frontend_client);
  ASSERT_TRUE(worker && frontend);

  std::vector<uint64_t> sequences;
  for (const char* data : {"queued", "started", "progress 50"}) {
    sequences.push_back(worker->append("job-a", data).value());
    ASSERT_THAT(worker->append("job-b", std::string("b ") + data), testing::IsOk());
  }
  EXPECT_LT(sequences[0], sequences[1]);
  EXPECT_LT(sequences[1], sequences[2]);

  auto from_start = frontend->follow("job-a", 0);
  ASSERT_THAT(from_start, testing::IsOk());
  auto first = (*from_start)->next(absl::Seconds(2));
  ASSERT_TRUE(first.ok() && first->has_value());
  EXPECT_EQ((*first)->data, "queued");
  EXPECT_EQ((*first)->sequence, sequences[0]);
  EXPECT_EQ(drain(**from_start, absl::Milliseconds(300)),
            (std::vector<std::string>{"started", "progress 50"}));

  // A client that saw "started" resumes after it, and then sees live events.
  auto resumed = frontend->follow("job-a", sequences[1] + 1);
  ASSERT_THAT(resumed, testing::IsOk());
  ASSERT_THAT(worker->append("job-a", "finished"), testing::IsOk());
  EXPECT_EQ(drain(**resumed, absl::Milliseconds(500)),
            (std::vector<std::string>{"progress 50", "finished"}));
}

TEST(EventLog, EventsOutliveANatsRestartAndGoWithTheirJob) {
  testing::NatsServer server(testing::scratch_dir("events-restart"));
  {
    auto client = connect(server);
    auto log = open_log(*client);
    ASSERT_THAT(log->append("job-a", "queued"), testing::IsOk());
    ASSERT_THAT(log->append("job-a", "started"), testing::IsOk());
  }
  server.restart();
  ASSERT_TRUE(server.running());
  auto client = connect(server);
  auto log = open_log(*client);
  ASSERT_NE(log, nullptr);
  auto follower = log->follow("job-a", 0);
  ASSERT_THAT(follower, testing::IsOk());
  EXPECT_EQ(drain(**follower, absl::Milliseconds(500)),
            (std::vector<std::string>{"queued", "started"}));
  ASSERT_THAT(log->remove("job-a"), testing::IsOk());
  auto after = log->follow("job-a", 0);
  ASSERT_THAT(after, testing::IsOk());
  EXPECT_TRUE(drain(**after, absl::Milliseconds(300)).empty());
}

}  // namespace
}  // namespace labelmesh::cluster
