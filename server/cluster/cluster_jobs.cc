// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/cluster_jobs.h"

#include "core/util/status_macros.h"

#include "absl/strings/str_cat.h"
#include "server/job_events.h"

namespace labelmesh::cluster {
namespace {

using server::has_ended;
using server::unix_now;

absl::StatusOr<v1::JobRecord> parse(const Versioned& stored, const std::string& job_id) {
  v1::JobRecord record;
  if (!record.ParseFromString(stored.value))
    return absl::DataLossError(absl::StrCat("job state ", job_id, " is unreadable"));
  return record;
}

// Which making of a job a queue message is for: its creation time in
// microseconds. A job made again under the same id (a client's request id
// reused after a delete) is queued again, and the old message is not taken
// for it.
std::string made(const v1::JobRecord& record) {
  return absl::StrCat(static_cast<int64_t>(record.job().created_at() * 1e6));
}

// What the queue's duplicate window knows a job's message by.
std::string queue_key(const v1::JobRecord& record) {
  return absl::StrCat(record.job().job_id(), ":", made(record));
}

}  // namespace

absl::Status ClusterJobs::log_state(const v1::JobRecord& record) {
  if (record.job().state() == v1::JOB_STATE_UNSPECIFIED) return absl::OkStatus();
  v1::JobEvent event = server::state_event(record.job(), 0);
  event.set_time(unix_now());
  return events_.append(record.job().job_id(), event.SerializeAsString()).status();
}

template <typename Change>
absl::StatusOr<v1::JobRecord> ClusterJobs::change_record(const std::string& job_id,
                                                         Change&& change) {
  for (;;) {
    LABELMESH_ASSIGN_OR_RETURN(auto stored, states_.get(job_id));
    auto record = parse(stored, job_id);
    if (!record.ok()) return record.status();
    LABELMESH_RETURN_IF_ERROR(change(*record));
    auto written = states_.update(job_id, record->SerializeAsString(), stored.revision);
    if (written.ok()) return record;
    if (written.status().code() != absl::StatusCode::kAborted) return written.status();
    // Another writer came in between: read again and decide again.
  }
}

absl::StatusOr<v1::JobRecord> ClusterJobs::submit(v1::JobRecord record) {
  const std::string job_id = record.job().job_id();
  if (job_id.empty()) return absl::InvalidArgumentError("a job to submit needs its id");
  record.mutable_job()->set_state(v1::JOB_STATE_QUEUED);
  record.mutable_job()->set_attempts(0);
  auto created = states_.create(job_id, record.SerializeAsString());
  if (created.status().code() == absl::StatusCode::kAlreadyExists) {
    // A retried submit: the job is recorded; queueing it again is harmless
    // (the queue's duplicate window drops it) and covers a submit that died
    // between the two steps.
    auto recorded = get(job_id);
    if (!recorded.ok()) return recorded.status();
    if (recorded->job().state() == v1::JOB_STATE_QUEUED) {
      LABELMESH_RETURN_IF_ERROR(queue_.enqueue(job_id, queue_key(*recorded), made(*recorded)));
    }
    return recorded;
  }
  if (!created.ok()) return created.status();
  if (auto queued = queue_.enqueue(job_id, queue_key(record), made(record)); !queued.ok()) {
    // Recorded but not queued: nobody would run it. The client hears the
    // error and retries.
    (void)states_.remove(job_id);
    return queued.status();
  }
  LABELMESH_RETURN_IF_ERROR(log_state(record));
  return record;
}

absl::StatusOr<v1::JobRecord> ClusterJobs::get(const std::string& job_id) {
  LABELMESH_ASSIGN_OR_RETURN(auto stored, states_.get(job_id));
  return parse(stored, job_id);
}

absl::StatusOr<Claim> ClusterJobs::claim(const std::string& job_id, const Delivered& from) {
  Claim claim{job_id, 0, {}};
  auto record = change_record(job_id, [&](v1::JobRecord& r) {
    if (has_ended(r.job().state())) {
      return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " has ended"));
    }
    if (!from.made.empty() && from.made != made(r)) {
      return absl::FailedPreconditionError(
          absl::StrCat("the message is for an earlier job ", job_id, ", since deleted"));
    }
    // A redelivery of the running message takes over from a silent worker;
    // any other message (a give-back whose old message came back) does not.
    if (r.job().state() == v1::JOB_STATE_RUNNING && from.message != 0 && r.queue_message() != 0 &&
        r.queue_message() != from.message) {
      return absl::FailedPreconditionError(absl::StrCat("another queue message runs job ", job_id));
    }
    r.set_queue_message(from.message);
    r.set_final_delivery(from.final_delivery);
    r.mutable_job()->set_state(v1::JOB_STATE_RUNNING);
    r.mutable_job()->set_attempts(r.job().attempts() + 1);
    r.mutable_job()->set_started_at(unix_now());
    r.mutable_job()->clear_stage();
    r.mutable_job()->set_progress(0);
    claim.attempt = r.job().attempts();
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  LABELMESH_RETURN_IF_ERROR(log_state(*record));
  claim.record = std::move(*record);
  return claim;
}

absl::StatusOr<v1::JobRecord> ClusterJobs::finish(const Claim& claim, v1::JobState state,
                                                  const v1::JobRecord& result) {
  if (!has_ended(state)) return absl::InvalidArgumentError("a job can only end as it ends");
  auto record = change_record(claim.job_id, [&](v1::JobRecord& r) {
    if (r.job().state() != v1::JOB_STATE_RUNNING || r.job().attempts() != claim.attempt) {
      return absl::AbortedError(absl::StrCat("job ", claim.job_id, " attempt ", claim.attempt,
                                             " is no longer the job's: its result is refused"));
    }
    auto* job = r.mutable_job();
    job->set_state(state);
    job->set_finished_at(unix_now());
    job->clear_stage();
    if (state == v1::JOB_STATE_SUCCEEDED) job->set_progress(1);
    if (result.job().has_report()) *job->mutable_report() = result.job().report();
    if (result.job().has_error()) *job->mutable_error() = result.job().error();
    *r.mutable_artifacts() = result.artifacts();
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  LABELMESH_RETURN_IF_ERROR(log_state(*record));
  return record;
}

absl::StatusOr<v1::JobRecord> ClusterJobs::cancel(const std::string& job_id) {
  auto record = change_record(job_id, [&](v1::JobRecord& r) {
    if (has_ended(r.job().state())) {
      return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " has ended"));
    }
    if (r.job().state() == v1::JOB_STATE_QUEUED) {
      r.mutable_job()->set_state(v1::JOB_STATE_CANCELLED);
      r.mutable_job()->set_finished_at(unix_now());
      r.mutable_job()->mutable_error()->set_code(static_cast<int>(absl::StatusCode::kCancelled));
      r.mutable_job()->mutable_error()->set_message("cancelled by a client");
    } else {
      r.set_cancel_requested(true);
    }
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  if (record->job().state() == v1::JOB_STATE_CANCELLED) {
    LABELMESH_RETURN_IF_ERROR(log_state(*record));
  }
  return record;
}

absl::Status ClusterJobs::publish(const Claim& claim, v1::JobEvent event) {
  event.set_job_id(claim.job_id);
  event.set_time(unix_now());
  return events_.append_async(claim.job_id, event.SerializeAsString());
}

absl::StatusOr<bool> ClusterJobs::remove(const std::string& job_id) {
  bool running = false;
  auto record = change_record(job_id, [&](v1::JobRecord& r) {
    running = r.job().state() == v1::JOB_STATE_RUNNING;
    if (running) {
      r.set_deleted(true);
      r.set_cancel_requested(true);
    }
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  if (running) return false;
  LABELMESH_RETURN_IF_ERROR(erase(job_id));
  return true;
}

absl::Status ClusterJobs::erase(const std::string& job_id) {
  LABELMESH_RETURN_IF_ERROR(states_.remove(job_id));
  return events_.remove(job_id);
}

absl::Status ClusterJobs::requeue(const Claim& claim) {
  auto record = change_record(claim.job_id, [&](v1::JobRecord& r) {
    if (r.job().state() != v1::JOB_STATE_RUNNING || r.job().attempts() != claim.attempt)
      return absl::AbortedError("another attempt holds the job");
    r.mutable_job()->set_state(v1::JOB_STATE_QUEUED);
    r.mutable_job()->set_started_at(0);
    r.mutable_job()->clear_stage();
    r.set_queue_message(0);
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  LABELMESH_RETURN_IF_ERROR(log_state(*record));
  return queue_
      .enqueue(claim.job_id, absl::StrCat(queue_key(claim.record), "@", claim.attempt),
               made(claim.record))
      .status();
}

absl::StatusOr<bool> ClusterJobs::give_up(const std::string& job_id, double started_before) {
  bool gave_up = false;
  auto record = change_record(job_id, [&](v1::JobRecord& r) {
    gave_up = r.job().state() == v1::JOB_STATE_RUNNING && r.final_delivery() &&
              r.job().started_at() < started_before;
    if (!gave_up) return absl::OkStatus();
    auto* job = r.mutable_job();
    job->set_state(v1::JOB_STATE_FAILED);
    job->set_finished_at(unix_now());
    job->clear_stage();
    job->mutable_error()->set_code(static_cast<int>(absl::StatusCode::kDeadlineExceeded));
    job->mutable_error()->set_message(absl::StrCat("the job's workers stopped answering (attempt ",
                                                   job->attempts(),
                                                   "): given up past the job timeout"));
    return absl::OkStatus();
  });
  if (!record.ok()) return record.status();
  if (gave_up) {
    LABELMESH_RETURN_IF_ERROR(log_state(*record));
  }
  return gave_up;
}

}  // namespace labelmesh::cluster
