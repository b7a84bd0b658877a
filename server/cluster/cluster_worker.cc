// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/cluster_worker.h"

#include "core/util/status_macros.h"

#include <future>

namespace labelmesh::cluster {

absl::StatusOr<bool> ClusterWorker::run_one() {
  LABELMESH_ASSIGN_OR_RETURN(auto taken, queue_.take(config_.poll));
  if (!taken.has_value()) return false;
  JobDelivery& delivery = *taken;
  const bool final_delivery = delivery.delivered() >= static_cast<uint64_t>(queue_.max_deliver());
  auto claim =
      jobs_.claim(delivery.job_id(), {delivery.made(), delivery.sequence(), final_delivery});
  if (claim.status().code() == absl::StatusCode::kFailedPrecondition ||
      claim.status().code() == absl::StatusCode::kNotFound) {
    // Ended, or deleted: nothing to run, and nothing to deliver again.
    LABELMESH_RETURN_IF_ERROR(delivery.ack());
    return true;
  }
  if (!claim.ok()) return claim.status();

  std::atomic<bool> cancelled = false;
  auto running =
      std::async(std::launch::async, [&] { return run_(claim->record, *claim, cancelled); });
  while (running.wait_for(absl::ToChronoMilliseconds(config_.heartbeat)) !=
         std::future_status::ready) {
    // The queue keeps the job ours while we say so; a failed heartbeat
    // (NATS away for a moment) only risks a second attempt, which the
    // attempt fencing settles.
    (void)delivery.in_progress();
    // A client's cancel, or another attempt that took the job over (this
    // worker was silent past the ack wait): either way the run stops.
    auto now = jobs_.get(delivery.job_id());
    if (now.ok() && (now->cancel_requested() || now->job().attempts() != claim->attempt ||
                     now->job().state() != v1::JOB_STATE_RUNNING))
      cancelled = true;
  }
  const JobOutcome outcome = running.get();
  if (outcome.state == v1::JOB_STATE_QUEUED) {
    // Given back (this worker is stopping, or has no room for results): the
    // next worker takes the job, without it counting as a failed delivery.
    auto requeued = jobs_.requeue(*claim);
    // Taken over meanwhile: the other attempt has it.
    if (!requeued.ok() && requeued.code() != absl::StatusCode::kAborted) return requeued;
    LABELMESH_RETURN_IF_ERROR(delivery.ack());
    return true;
  }
  auto ended = jobs_.finish(*claim, outcome.state, outcome.result);
  if (ended.status().code() == absl::StatusCode::kAborted) {
    if (ended_) ended_(*claim, ended);
    return true;
  }
  if (ended.status().code() == absl::StatusCode::kNotFound) {
    LABELMESH_RETURN_IF_ERROR(delivery.ack());
    return true;
  }
  if (!ended.ok()) return ended.status();
  if (ended_) ended_(*claim, ended);
  LABELMESH_RETURN_IF_ERROR(delivery.ack());
  return true;
}

}  // namespace labelmesh::cluster
