// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/job_events.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace labelmesh::server {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool has_ended(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

google::protobuf::Timestamp to_timestamp(double unix_seconds) {
  google::protobuf::Timestamp stamp;
  const double whole = std::floor(unix_seconds);
  stamp.set_seconds(static_cast<int64_t>(whole));
  stamp.set_nanos(std::min(999'999'999, static_cast<int>((unix_seconds - whole) * 1e9)));
  return stamp;
}

v1::JobEvent state_event(const v1::Job& job, uint32_t position) {
  v1::JobEvent event;
  event.set_job_id(job.job_id());
  switch (job.state()) {
    case v1::JOB_STATE_SUCCEEDED:
      *event.mutable_finished()->mutable_report() = job.report();
      break;
    case v1::JOB_STATE_FAILED:
      *event.mutable_failed() = job.error();
      break;
    case v1::JOB_STATE_CANCELLED:
      event.mutable_cancelled();
      break;
    case v1::JOB_STATE_RUNNING:
      event.mutable_started()->set_attempt(job.attempts());
      break;
    default:
      event.mutable_queued()->set_position(position);
  }
  return event;
}

}  // namespace labelmesh::server
