// SPDX-License-Identifier: AGPL-3.0-or-later
// Every job's events (queued, started, progress, finished...) in one NATS
// JetStream stream on file storage, one subject per job. Any frontend can
// follow a job from any point: each event's stream sequence is its place,
// which a client that lost its Watch stream gives back to resume.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/cluster/nats_client.h"

namespace labelmesh::cluster {

struct EventLogConfig {
  std::string stream = "LABELMESH_EVENTS";
  std::string subject_prefix = "labelmesh.events";
  // Events older than this are dropped (jobs' results outlive them in the
  // job states).
  absl::Duration max_age = absl::Hours(24 * 7);
};

struct LoggedEvent {
  uint64_t sequence = 0;  // the event's place in the stream, above 0
  std::string data;
};

// One job's events in order, from where the follow began.
class EventFollower {
 public:
  explicit EventFollower(natsSubscription* subscription) : subscription_(subscription) {}
  ~EventFollower();
  EventFollower(const EventFollower&) = delete;
  EventFollower& operator=(const EventFollower&) = delete;

  // The next event, waiting at most `wait`; nullopt when none came.
  absl::StatusOr<std::optional<LoggedEvent>> next(absl::Duration wait);

 private:
  natsSubscription* subscription_;
};

// A live follow of one job's events, each handed to a callback on the NATS
// client's own thread, so a follower holds no thread while it waits.
class EventSubscription {
 public:
  struct Delivery;
  EventSubscription(natsSubscription* subscription, Delivery* delivery)
      : subscription_(subscription), delivery_(delivery) {}
  // Once it returns, the callback is not called again.
  ~EventSubscription();
  EventSubscription(const EventSubscription&) = delete;
  EventSubscription& operator=(const EventSubscription&) = delete;

 private:
  natsSubscription* subscription_;
  Delivery* delivery_;
};

class EventLog {
 public:
  // Creates the stream unless it exists. Errors: those of nats_error.
  static absl::StatusOr<std::unique_ptr<EventLog>> open(NatsClient& client,
                                                        const EventLogConfig& config);

  // Appends an event to `job_id`'s; its sequence.
  absl::StatusOr<uint64_t> append(const std::string& job_id, const std::string& data);
  // Appends without waiting for the server's confirmation: for the many
  // stage and progress events of a run, which the record does not depend
  // on. Events of one connection keep their order.
  absl::Status append_async(const std::string& job_id, const std::string& data);
  // `job_id`'s newest event; nullopt when it has none.
  absl::StatusOr<std::optional<std::string>> last(const std::string& job_id);

  // Follows `job_id`'s events from sequence `from` on (0: from its first).
  absl::StatusOr<std::unique_ptr<EventFollower>> follow(const std::string& job_id, uint64_t from);

  // Hands each of `job_id`'s events from sequence `from` on (0: from its
  // first) to `on_event`, as they come.
  absl::StatusOr<std::unique_ptr<EventSubscription>> subscribe(
      const std::string& job_id, uint64_t from, std::function<void(LoggedEvent)> on_event);
  // Drops every event of `job_id`.
  absl::Status remove(const std::string& job_id);

 private:
  EventLog(NatsClient& client, EventLogConfig config)
      : client_(client), config_(std::move(config)) {}
  std::string subject(const std::string& job_id) const;
  // Ordered consumer options for one job's events from `from`.
  jsSubOptions follow_options(uint64_t from) const;

  NatsClient& client_;
  EventLogConfig config_;
};

}  // namespace labelmesh::cluster
