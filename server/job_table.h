// SPDX-License-Identifier: AGPL-3.0-or-later
// Every job one server knows (the single-machine JobStore): the queue, each job's state and event
// history, and the waits of workers and watchers. Each state change is written to the spool before
// it is visible to anyone.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "labelmesh/v1/service.pb.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/spool.h"

namespace labelmesh::server {

class JobTable final : public JobStore {
 public:
  JobTable(const Spool& spool, int queue_capacity, Metrics& metrics);

  // Loads the spool: queued and interrupted jobs are queued again in their
  // order of arrival; ended jobs stay fetchable until `result_ttl` after they
  // ended, older ones are deleted.
  void recover(absl::Duration result_ttl);

  std::string new_job_id_for(const std::string& owner, const std::string& request_id) override;
  std::string upload_path(const std::string& job_id, const std::string& extension) override;
  absl::StatusOr<uint64_t> free_bytes() const override;
  std::string artifact_path(const v1::Job& job, const std::string& name) const override;

  bool queue_full() const override;
  absl::StatusOr<uint32_t> accept(v1::JobRecord record, const std::string& upload_path) override;

  // Blocks for the next queued job and marks it running; nullopt after close().
  std::optional<v1::JobRecord> take_next();
  // A running job's stage and progress events, as its worker sends them.
  void publish(const std::string& job_id, v1::JobEvent event);
  void succeed(const std::string& job_id, const v1::Report& report,
               std::vector<v1::Artifact> artifacts);
  void fail(const std::string& job_id, int code, const std::string& message);
  void mark_cancelled(const std::string& job_id);
  // A running job stopped by shutdown: queued again on disk for the next start.
  void requeue_interrupted(const std::string& job_id);
  // A running job its worker could not start (no room for results): first in
  // the queue again, its attempt not counted.
  void give_back(const std::string& job_id);
  // False once dispatch stopped or the table closed: no job will be handed out.
  bool dispatching() const;

  absl::StatusOr<v1::Job> get(const std::string& job_id) const override;
  absl::StatusOr<std::string> owner(const std::string& job_id) const override;

  absl::StatusOr<JobPage> list(const JobQuery& query) const override;

  std::optional<PriorRequest> find_request(const std::string& owner,
                                           const std::string& request_id) const override;

  // The spool's error when a queued job's cancellation cannot be saved.
  absl::StatusOr<v1::JobState> remove(const std::string& job_id) override;
  // The spool's error (RESOURCE_EXHAUSTED when its disk is full) when the
  // cancelled record cannot be saved, and the job stays queued.
  absl::StatusOr<v1::Job> cancel(const std::string& job_id) override;
  bool cancel_requested(const std::string& job_id) const;
  absl::StatusOr<std::vector<v1::Artifact>> artifacts(const std::string& job_id) const override;

  absl::Status listen(const std::string& job_id, uint64_t from, EventListener* listener) override;
  void unlisten(const std::string& job_id, EventListener* listener) override;

  std::vector<std::string> expire(absl::Duration result_ttl, size_t max_ended) override;
  // Wakes every waiter; take_next() returns nullopt from now on.
  void close();
  // Stops handing out jobs but still accepts them (drain before shutdown).
  void stop_dispatch();

 private:
  struct Entry {
    v1::JobRecord record;
    std::vector<v1::JobEvent> events;
    bool cancel_requested = false;
    // Deleted by a client while running: gone once its worker ends.
    bool remove_when_ended = false;
    std::vector<EventListener*> listeners;
  };

  Entry* find(const std::string& job_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  const Entry* find(const std::string& job_id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // As clients see the table: a job deleted while it runs is gone already.
  Entry* find_visible(const std::string& job_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  const Entry* find_visible(const std::string& job_id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // Appends an event (sequence and time set here) and wakes watchers.
  void add_event(Entry& entry, v1::JobEvent event) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // Saves to the spool; a failure is logged and counted, and returned.
  absl::Status persist(const v1::JobRecord& record);
  // What an end does when its record cannot be saved: a client's request is
  // refused with the spool's error and changes nothing; an end the worker
  // reached is applied in memory (on disk the job stays unended, so after a
  // restart it runs again and nothing is lost). `error`, if given, becomes
  // the job's error with the same save.
  enum class Unsaved { kRefuse, kApply };
  absl::Status end_job(Entry& entry, v1::JobState state, v1::JobEvent event, Unsaved unsaved,
                       const v1::JobError* error = nullptr) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::Status end_cancelled(Entry& entry, Unsaved unsaved) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // Deletes the job if a client asked while it ran. Returns true if it did.
  bool remove_if_requested(const std::string& job_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // The job as clients see it: queue position and timestamps filled in.
  v1::Job view(const std::string& job_id, const v1::Job& job) const
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  uint32_t position_of(const std::string& job_id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // Removes the job from the table (not the spool), closing its listeners.
  void erase_entry(const std::string& job_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  void update_gauges() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  // take_next's wait: a job to hand out, or the table closed.
  bool ready_to_dispatch() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);

  const Spool& spool_;
  const size_t queue_capacity_;
  Metrics& metrics_;

  // Waits (take_next) are on conditions the mutex re-checks as it is
  // released: no condition variable to signal.
  mutable absl::Mutex mutex_;
  std::map<std::string, Entry> jobs_ ABSL_GUARDED_BY(mutex_);
  std::deque<std::string> queue_ ABSL_GUARDED_BY(mutex_);
  size_t running_ ABSL_GUARDED_BY(mutex_) = 0;
  uint64_t next_sequence_ ABSL_GUARDED_BY(mutex_) = 1;
  bool closed_ ABSL_GUARDED_BY(mutex_) = false;
  bool dispatching_ ABSL_GUARDED_BY(mutex_) = true;
};

}  // namespace labelmesh::server
