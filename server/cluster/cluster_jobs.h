// SPDX-License-Identifier: AGPL-3.0-or-later
// A job's life when frontends and workers run on different machines: its
// record in the job states (key-value, every change naming the revision it
// read), its id in the job queue, its events in the event log. Delivery is
// at least once, so every step is safe to repeat: a submit of a known id
// gives the job back, a claim bumps the attempt, and only the worker
// holding the current attempt can end the job; any other (one the queue
// gave up on, come back late) is refused, and the job ends exactly once.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "labelmesh/v1/service.pb.h"
#include "server/cluster/event_log.h"
#include "server/cluster/job_queue.h"
#include "server/cluster/job_states.h"

namespace labelmesh::cluster {

// A worker's hold on a job: the attempt it runs, and the record as it
// claimed it.
struct Claim {
  std::string job_id;
  uint32_t attempt = 0;
  v1::JobRecord record;
};

// Which queue message delivered a job to a worker (all empty: unknown).
struct Delivered {
  std::string made;             // JobDelivery::made
  uint64_t message = 0;         // JobDelivery::sequence
  bool final_delivery = false;  // the queue delivers this message no more
};

class ClusterJobs {
 public:
  ClusterJobs(JobStates& states, JobQueue& queue, EventLog& events)
      : states_(states), queue_(queue), events_(events) {}

  // Records `record` (its job id set) as QUEUED and queues it. A job id
  // already recorded gives its record back unchanged (a retried submit).
  absl::StatusOr<v1::JobRecord> submit(v1::JobRecord record);

  // The job's record. Errors: NOT_FOUND.
  absl::StatusOr<v1::JobRecord> get(const std::string& job_id);

  // Starts the next attempt of a delivered job: QUEUED, or RUNNING under a
  // worker the queue gave up on, becomes RUNNING with one more attempt.
  // `from` tells which queue message delivered it (all empty: not checked).
  // Errors: FAILED_PRECONDITION when the job has ended, when the delivery
  // was for an earlier job of the same id, or when another message's
  // delivery runs the job (the delivery is done with in every case);
  // NOT_FOUND.
  absl::StatusOr<Claim> claim(const std::string& job_id, const Delivered& from = Delivered());

  // Ends a claimed job in `state` (SUCCEEDED, FAILED or CANCELLED) with
  // `result` filling the record's report, artifacts or error, and logs it.
  // Errors: ABORTED when the claim is no longer the job's current attempt
  // (the result is refused); INVALID_ARGUMENT for a state that is not an end.
  absl::StatusOr<v1::JobRecord> finish(const Claim& claim, v1::JobState state,
                                       const v1::JobRecord& result);

  // A running claim's stage or progress event, logged for watchers without
  // waiting for NATS to confirm it (GetJob reads a running job's stage from
  // its newest event).
  absl::Status publish(const Claim& claim, v1::JobEvent event);
  // A running job is marked deleted and asked to stop: its worker removes
  // it once it ends. Any other is removed at once (record and events);
  // true when it was. Errors: NOT_FOUND.
  absl::StatusOr<bool> remove(const std::string& job_id);
  // The record and events of `job_id`, whatever its state.
  absl::Status erase(const std::string& job_id);
  // Puts a claimed job back in the queue under a message of its own, QUEUED
  // again, for a worker that stops before the job ends (a redelivery would
  // count towards the queue's most deliveries). Errors: ABORTED when the
  // claim is no longer the job's current attempt.
  absl::Status requeue(const Claim& claim);
  // A job RUNNING on the queue's final delivery since before
  // `started_before` (seconds since 1970): its last worker died, past any
  // run's timeout, and no delivery will come. It ends FAILED
  // (DEADLINE_EXCEEDED); true when it did.
  absl::StatusOr<bool> give_up(const std::string& job_id, double started_before);
  // Every job id recorded.
  absl::StatusOr<std::vector<std::string>> job_ids() { return states_.keys(); }

  // A queued job ends CANCELLED; a running one is asked to stop (its
  // worker sees cancel_requested). Errors: FAILED_PRECONDITION when it has
  // ended; NOT_FOUND.
  absl::StatusOr<v1::JobRecord> cancel(const std::string& job_id);

 private:
  // Reads, changes and writes the record until no other writer came in
  // between; `change` returns an error to give up.
  template <typename Change>
  absl::StatusOr<v1::JobRecord> change_record(const std::string& job_id, Change&& change);
  absl::Status log_state(const v1::JobRecord& record);

  JobStates& states_;
  JobQueue& queue_;
  EventLog& events_;
};

}  // namespace labelmesh::cluster
