// SPDX-License-Identifier: AGPL-3.0-or-later
// The jobs waiting for a worker, as a NATS JetStream work queue: a stream
// on file storage (queued jobs outlive a NATS restart) that drops each job
// once a worker acknowledges it, read through one durable pull consumer
// that every worker shares. A job id published twice within the duplicate
// window is stored once. A worker that takes a job must acknowledge it
// within the ack wait, or say it is still working on it; otherwise (it
// died) the job goes to the next worker, up to max_deliver times in all.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/cluster/nats_client.h"

namespace labelmesh::cluster {

struct JobQueueConfig {
  std::string stream = "LABELMESH_JOBS";
  std::string subject = "labelmesh.jobs";
  std::string consumer = "workers";
  absl::Duration ack_wait = absl::Seconds(30);
  int max_deliver = 3;
  absl::Duration duplicate_window = absl::Hours(24);
};

// One job handed to this worker; exactly one of ack, nak and term ends it.
class JobDelivery {
 public:
  JobDelivery(natsMsg* message, std::string job_id, std::string made, uint64_t delivered,
              uint64_t sequence = 0)
      : message_(message),
        job_id_(std::move(job_id)),
        made_(std::move(made)),
        delivered_(delivered),
        sequence_(sequence) {}
  ~JobDelivery();
  JobDelivery(JobDelivery&& other) noexcept;
  JobDelivery& operator=(JobDelivery&&) = delete;
  JobDelivery(const JobDelivery&) = delete;

  const std::string& job_id() const { return job_id_; }
  // Which making of the job this message was queued for (as enqueue was
  // told), so that a message left from a deleted job is not taken for a new
  // job under the same id; empty when not told.
  const std::string& made() const { return made_; }
  // 1 the first time this job was handed out, more after redeliveries.
  // The message's place in the queue stream: the same for every delivery
  // of one message.
  uint64_t sequence() const { return sequence_; }
  uint64_t delivered() const { return delivered_; }

  // Done (finished, failed or cancelled): the queue drops the job. Waits
  // for the server's confirmation.
  absl::Status ack();
  // Not now: the job goes back to the queue after `delay`.
  absl::Status nak(absl::Duration delay = absl::ZeroDuration());
  // Still working: the ack wait starts again.
  absl::Status in_progress();
  // Never: the job is not delivered again.
  absl::Status term();

 private:
  natsMsg* message_;
  std::string job_id_;
  std::string made_;
  uint64_t delivered_;
  uint64_t sequence_;
};

class JobQueue {
 public:
  // The most deliveries of one message (JobQueueConfig::max_deliver).
  int max_deliver() const { return config_.max_deliver; }
  // Creates the stream and the consumer unless they exist (then they are
  // used as they are) and subscribes to the consumer.
  // Errors: those of nats_error, naming the stream or the consumer.
  static absl::StatusOr<std::unique_ptr<JobQueue>> open(NatsClient& client,
                                                        const JobQueueConfig& config);
  ~JobQueue();
  JobQueue(const JobQueue&) = delete;
  JobQueue& operator=(const JobQueue&) = delete;

  // Queues `job_id` (made as `made`, see JobDelivery::made); false when
  // `dedupe_key` (empty: the job id) was already queued within the
  // duplicate window (the queue holds it once).
  absl::StatusOr<bool> enqueue(const std::string& job_id, const std::string& dedupe_key = "",
                               const std::string& made = "");

  // The next job, waiting at most `wait`; nullopt when none came.
  absl::StatusOr<std::optional<JobDelivery>> take(absl::Duration wait);

  // Jobs stored in the stream: queued or handed out and not yet acknowledged.
  absl::StatusOr<uint64_t> stored();

 private:
  JobQueue(NatsClient& client, JobQueueConfig config, natsSubscription* subscription)
      : client_(client), config_(std::move(config)), subscription_(subscription) {}
  NatsClient& client_;
  JobQueueConfig config_;
  natsSubscription* subscription_;
};

}  // namespace labelmesh::cluster
