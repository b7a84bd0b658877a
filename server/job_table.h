// SPDX-License-Identifier: AGPL-3.0-or-later
// Every job the server knows: the queue, each job's state and event history,
// and the waits of workers and watchers. Each state change is written to the
// spool before it is visible to anyone.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "labelmesh/v1/service.pb.h"
#include "server/metrics.h"
#include "server/spool.h"

namespace labelmesh::server {

class JobTable {
 public:
  JobTable(const Spool& spool, int queue_capacity, Metrics& metrics);

  // Loads the spool: queued and interrupted jobs are queued again in their
  // order of arrival; ended jobs stay fetchable until `result_ttl` after they
  // ended, older ones are deleted.
  void recover(absl::Duration result_ttl);

  bool queue_full() const;
  // Moves the upload into a new job and queues it; returns the queue position.
  // RESOURCE_EXHAUSTED when the queue is full, UNAVAILABLE after close().
  absl::StatusOr<uint32_t> accept(v1::JobRecord record, const std::string& upload_path);

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

  // NOT_FOUND for an unknown id.
  absl::StatusOr<v1::Job> get(const std::string& job_id) const;
  // The identity that submitted the job; NOT_FOUND for an unknown id.
  absl::StatusOr<std::string> owner(const std::string& job_id) const;

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
  absl::StatusOr<JobPage> list(const JobQuery& query) const;

  // The job `owner` submitted with `request_id`, if any.
  struct PriorRequest {
    std::string job_id;
    std::string sha256;
    uint32_t queue_position = 0;
  };
  std::optional<PriorRequest> find_request(const std::string& owner,
                                           const std::string& request_id) const;

  // Deletes a job with its input and results; a running job is stopped and
  // deleted when its worker has gone. Returns the state it was in. The
  // spool's error when a queued job's cancellation cannot be saved.
  absl::StatusOr<v1::JobState> remove(const std::string& job_id);
  // A queued job is cancelled at once; a running one is flagged for its
  // worker to stop. FAILED_PRECONDITION for a job that ended; the spool's
  // error (RESOURCE_EXHAUSTED when its disk is full) when the cancelled
  // record cannot be saved, and the job stays queued.
  absl::StatusOr<v1::Job> cancel(const std::string& job_id);
  bool cancel_requested(const std::string& job_id) const;
  // FAILED_PRECONDITION unless the job succeeded.
  absl::StatusOr<std::vector<v1::Artifact>> artifacts(const std::string& job_id) const;

  // Told of a job's events as they are added, with no thread of its own.
  // Called with the table locked: it must not call the table back.
  class EventListener {
   public:
    virtual ~EventListener() = default;
    // `last`: the job ended and this is its last event.
    virtual void on_event(const v1::JobEvent& event, bool last) = 0;
    // No event follows: OK when the job had ended with nothing left to
    // replay, NOT_FOUND when it was deleted, UNAVAILABLE at shutdown.
    virtual void on_closed(const absl::Status& status) = 0;
  };
  // Replays the job's events from `from` to `listener`, then tells it of
  // each new one. NOT_FOUND for an unknown job, UNAVAILABLE after close().
  absl::Status listen(const std::string& job_id, uint64_t from, EventListener* listener);
  // Once this returns, `listener` is not called again.
  void unlisten(const std::string& job_id, EventListener* listener);

  // Deletes jobs that ended more than `result_ttl` ago, and the oldest ended
  // jobs beyond `max_ended`; returns their ids.
  std::vector<std::string> expire(absl::Duration result_ttl, size_t max_ended);
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

  Entry* find(const std::string& job_id);
  const Entry* find(const std::string& job_id) const;
  // As clients see the table: a job deleted while it runs is gone already.
  Entry* find_visible(const std::string& job_id);
  const Entry* find_visible(const std::string& job_id) const;
  // Appends an event (sequence and time set here) and wakes watchers.
  void add_event(Entry& entry, v1::JobEvent event);
  // Saves to the spool; a failure is logged and counted, and returned.
  absl::Status persist(const v1::JobRecord& record);
  // What an end does when its record cannot be saved: a client's request is
  // refused with the spool's error and changes nothing; an end the worker
  // reached is applied in memory (on disk the job stays unended, so after a
  // restart it runs again and nothing is lost). `error`, if given, becomes
  // the job's error with the same save.
  enum class Unsaved { kRefuse, kApply };
  absl::Status end_job(Entry& entry, v1::JobState state, v1::JobEvent event, Unsaved unsaved,
                       const v1::JobError* error = nullptr);
  absl::Status end_cancelled(Entry& entry, Unsaved unsaved);
  // Deletes the job if a client asked while it ran. Returns true if it did.
  bool remove_if_requested(const std::string& job_id);
  // The job as clients see it: queue position and timestamps filled in.
  v1::Job view(const std::string& job_id, const v1::Job& job) const;
  uint32_t position_of(const std::string& job_id) const;
  // Removes the job from the table (not the spool), closing its listeners.
  void erase_entry(const std::string& job_id);
  void update_gauges();

  const Spool& spool_;
  const size_t queue_capacity_;
  Metrics& metrics_;

  mutable std::mutex mutex_;
  std::condition_variable queue_changed_;
  std::map<std::string, Entry> jobs_;
  std::deque<std::string> queue_;
  size_t running_ = 0;
  uint64_t next_sequence_ = 1;
  bool closed_ = false;
  bool dispatching_ = true;
};

double unix_now();

}  // namespace labelmesh::server
