// SPDX-License-Identifier: AGPL-3.0-or-later
// What the gRPC service needs of the jobs behind it: accept an upload as a
// job, look jobs up, list, cancel and delete them, follow their events and
// find their files. One machine keeps them in a job table over a local
// spool (job_table.h); several keep them in NATS JetStream and a shared
// directory (cluster/cluster_job_store.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "labelmesh/v1/service.pb.h"
#include "server/job_events.h"

namespace labelmesh::server {

class JobStore {
 public:
  virtual ~JobStore() = default;

  // The id a new job of `owner` gets; `request_id` is the client's (may be
  // empty).
  virtual std::string new_job_id_for(const std::string& owner, const std::string& request_id) = 0;
  // Where the upload of a job about to be made is received.
  virtual std::string upload_path(const std::string& job_id, const std::string& extension) = 0;
  // Bytes an unprivileged writer may still use where uploads and results go.
  virtual absl::StatusOr<uint64_t> free_bytes() const = 0;

  virtual bool queue_full() const = 0;
  // UNAVAILABLE while the store cannot take jobs (a cluster frontend cut off
  // from NATS): checked before an upload is received.
  virtual absl::Status available() const { return absl::OkStatus(); }
  // Moves the upload into a new job and queues it; returns the queue position.
  // RESOURCE_EXHAUSTED when the queue is full, UNAVAILABLE after close().
  virtual absl::StatusOr<uint32_t> accept(v1::JobRecord record, const std::string& upload_path) = 0;

  // NOT_FOUND for an unknown id.
  virtual absl::StatusOr<v1::Job> get(const std::string& job_id) const = 0;
  // The identity that submitted the job; NOT_FOUND for an unknown id.
  virtual absl::StatusOr<std::string> owner(const std::string& job_id) const = 0;

  struct JobQuery {
    // Only this owner's jobs; empty for every owner's.
    std::string owner;
    std::vector<v1::JobState> states;
    size_t page_size = 100;
    std::string page_token;
  };
  struct JobPage {
    std::vector<v1::Job> jobs;
    std::string next_page_token;
  };
  // Newest first, without reports. INVALID_ARGUMENT for a page token that
  // no reply gave.
  virtual absl::StatusOr<JobPage> list(const JobQuery& query) const = 0;

  // The job `owner` submitted with `request_id`, if any.
  struct PriorRequest {
    std::string job_id;
    std::string sha256;
    uint32_t queue_position = 0;
  };
  virtual std::optional<PriorRequest> find_request(const std::string& owner,
                                                   const std::string& request_id) const = 0;

  // Deletes a job with its input and results; a running job is stopped and
  // deleted when its worker has gone. Returns the state it was in.
  virtual absl::StatusOr<v1::JobState> remove(const std::string& job_id) = 0;
  // A queued job is cancelled at once; a running one is flagged for its
  // worker to stop. FAILED_PRECONDITION for a job that ended.
  virtual absl::StatusOr<v1::Job> cancel(const std::string& job_id) = 0;
  // FAILED_PRECONDITION unless the job succeeded.
  virtual absl::StatusOr<std::vector<v1::Artifact>> artifacts(const std::string& job_id) const = 0;
  // The file holding artifact `name` of `job` (as get() gave it).
  virtual std::string artifact_path(const v1::Job& job, const std::string& name) const = 0;

  // Told of a job's events as they are added. It must not call the store
  // back from on_event or on_closed.
  class EventListener {
   public:
    virtual ~EventListener() = default;
    // `last`: the job ended and this is its last event.
    virtual void on_event(const v1::JobEvent& event, bool last) = 0;
    // No event follows: OK when the job had ended with nothing left to
    // replay, NOT_FOUND when it was deleted, UNAVAILABLE at shutdown.
    virtual void on_closed(const absl::Status& status) = 0;
  };
  // Replays the job's events from sequence `from` to `listener`, then tells
  // it of each new one. NOT_FOUND for an unknown job, UNAVAILABLE after
  // close().
  virtual absl::Status listen(const std::string& job_id, uint64_t from,
                              EventListener* listener) = 0;
  // Once this returns, `listener` is not called again.
  virtual void unlisten(const std::string& job_id, EventListener* listener) = 0;

  // Deletes jobs that ended more than `result_ttl` ago, and the oldest ended
  // jobs beyond `max_ended`; returns their ids.
  virtual std::vector<std::string> expire(absl::Duration result_ttl, size_t max_ended) = 0;
};

// The job as clients see it: timestamps as Timestamp messages too.
v1::Job with_timestamps(v1::Job job);

// A ListJobs page over `jobs` (any order); INVALID_ARGUMENT for a bad token.
absl::StatusOr<JobStore::JobPage> page_of(std::vector<v1::Job> jobs,
                                          const JobStore::JobQuery& query);

}  // namespace labelmesh::server
