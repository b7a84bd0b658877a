// SPDX-License-Identifier: AGPL-3.0-or-later
// The jobs as a frontend of a cluster sees them: records in the shared job
// states, events in the event log, uploads and results in the shared
// directory. A frontend holds nothing of its own, so any frontend answers
// for any job, and one that dies loses nothing.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "server/cluster/cluster_connection.h"
#include "server/cluster/shared_artifacts.h"
#include "server/job_store.h"

namespace labelmesh::server {

class ClusterJobStore final : public JobStore {
 public:
  // A job RUNNING for longer than `abandoned_after` has lost its workers
  // (every run ends within the job timeout): expire() fails it.
  ClusterJobStore(cluster::ClusterConnection& cluster, const cluster::SharedArtifacts& files,
                  int queue_capacity, absl::Duration abandoned_after)
      : cluster_(cluster),
        files_(files),
        queue_capacity_(static_cast<uint64_t>(queue_capacity)),
        abandoned_after_(abandoned_after) {}
  ~ClusterJobStore() override { close(); }

  // A retried Submit (same owner and request_id) gets the same id on any
  // frontend, so that the job states make it one job.
  std::string new_job_id_for(const std::string& owner, const std::string& request_id) override;
  // Under the shared directory's uploads/, a name of its own per upload.
  std::string upload_path(const std::string& job_id, const std::string& extension) override;
  absl::StatusOr<uint64_t> free_bytes() const override;

  // Full when the queue stream holds `queue_capacity` jobs (queued or
  // running).
  bool queue_full() const override;
  // Puts job.pb and the input in the job's shared directory, then records
  // and queues the job. The position is the number of jobs ahead in the
  // stream, running ones included.
  absl::StatusOr<uint32_t> accept(v1::JobRecord record, const std::string& upload_path) override;
  absl::StatusOr<v1::Job> get(const std::string& job_id) const override;
  absl::StatusOr<std::string> owner(const std::string& job_id) const override;
  absl::StatusOr<JobPage> list(const JobQuery& query) const override;
  std::optional<PriorRequest> find_request(const std::string& owner,
                                           const std::string& request_id) const override;
  absl::StatusOr<v1::JobState> remove(const std::string& job_id) override;
  absl::StatusOr<v1::Job> cancel(const std::string& job_id) override;
  absl::StatusOr<std::vector<v1::Artifact>> artifacts(const std::string& job_id) const override;
  std::string artifact_path(const v1::Job& job, const std::string& name) const override;
  // An ended job's events are replayed here; a live one's come on the NATS
  // client's thread.
  absl::Status listen(const std::string& job_id, uint64_t from, EventListener* listener) override;
  void unlisten(const std::string& job_id, EventListener* listener) override;
  // Any frontend may expire a job; doing it twice is harmless. Also fails
  // jobs RUNNING past `abandoned_after`.
  std::vector<std::string> expire(absl::Duration result_ttl, size_t max_ended) override;
  // Ends the follows the event log alone would leave waiting: of a job
  // deleted meanwhile (NOT_FOUND), and of a job whose record has ended
  // while its last event has not come for a few seconds (the record tells
  // it). For the housekeeping loop.
  void check_follows();

  // Deletes uploads older than `age` from the shared uploads/ directory:
  // those of a frontend that died while receiving them. Returns how many.
  size_t remove_abandoned_uploads(absl::Duration age) const;
  // False while this frontend cannot reach NATS.
  bool connected() const { return cluster_.client->connected(); }
  absl::Status available() const override {
    if (connected()) return absl::OkStatus();
    return absl::UnavailableError("the cluster's NATS server is unreachable; try again later");
  }

  // Closes every follow (UNAVAILABLE); listen() refuses from now on.
  void close();

 private:
  // The record unless deleted. Errors: NOT_FOUND; those of NATS.
  absl::StatusOr<v1::JobRecord> record(const std::string& job_id) const;
  // Replays an ended job's events to its end (or tells it where the job
  // stands when they are gone).
  absl::Status replay_ended(const v1::JobRecord& record, uint64_t from, EventListener* listener);
  // Removes the job's record, events and files.
  absl::Status erase(const std::string& job_id) const;

  struct Follow {
    std::string job_id;
    std::unique_ptr<cluster::EventSubscription> subscription;
    // Set once the listener was handed the job's last event.
    std::shared_ptr<std::atomic<bool>> heard_last;
    // When a check first found the job's record ended, else 0.
    double ended_seen = 0;
  };
  // What to tell a listener whose follow the store ends itself.
  struct Ending {
    EventListener* listener;
    Follow follow;
    absl::Status status;
    std::optional<v1::JobEvent> last_event;
  };
  // Stops the follows (outside the lock), tells their listeners, and lets
  // their unlisten calls, which wait meanwhile, go on.
  void end_follows(std::vector<Ending> endings);

  cluster::ClusterConnection& cluster_;
  const cluster::SharedArtifacts& files_;
  const uint64_t queue_capacity_;
  const absl::Duration abandoned_after_;

  absl::Mutex mutex_;
  bool closed_ ABSL_GUARDED_BY(mutex_) = false;
  std::map<EventListener*, Follow> follows_ ABSL_GUARDED_BY(mutex_);
  // Listeners being told their follow ended; unlisten waits for them.
  std::set<EventListener*> ending_ ABSL_GUARDED_BY(mutex_);
};

// The event a logged one is to a watcher: its sequence is its place in the
// log, its time also as a Timestamp.
v1::JobEvent watched_event(const cluster::LoggedEvent& logged);

}  // namespace labelmesh::server
