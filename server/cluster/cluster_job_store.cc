// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/cluster_job_store.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/digest/sha256.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "server/spool.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace fs = std::filesystem;
namespace {

// Longest an ended job's replay waits for an event it knows is logged.
constexpr absl::Duration kReplayWait = absl::Milliseconds(500);
// How long a follow waits for the last event of a job whose record has
// ended before the record stands in for it.
constexpr absl::Duration kLastEventWait = absl::Seconds(5);

bool is_last(const v1::JobEvent& event) {
  return event.has_finished() || event.has_failed() || event.has_cancelled();
}

// The same on every frontend for the same client and request.
std::string job_id_of_request(const std::string& owner, const std::string& request_id) {
  digest::Sha256 hash;
  hash.update(absl::StrCat("labelmesh request\n", owner, "\n", request_id));
  return hash.hex_digest().substr(0, 32);
}

}  // namespace

v1::JobEvent watched_event(const cluster::LoggedEvent& logged) {
  v1::JobEvent event;
  if (!event.ParseFromString(logged.data)) event.Clear();
  event.set_sequence(logged.sequence);
  if (event.time() > 0) *event.mutable_timestamp() = to_timestamp(event.time());
  return event;
}

std::string ClusterJobStore::new_job_id_for(const std::string& owner,
                                            const std::string& request_id) {
  return request_id.empty() ? new_job_id() : job_id_of_request(owner, request_id);
}

std::string ClusterJobStore::upload_path(const std::string& job_id, const std::string& extension) {
  // Two frontends may receive the same retried request at once.
  return absl::StrCat(files_.root(), "/uploads/", job_id, "-", new_job_id().substr(0, 8),
                      extension);
}

absl::StatusOr<uint64_t> ClusterJobStore::free_bytes() const { return files_.free_bytes(); }

bool ClusterJobStore::queue_full() const {
  auto stored = cluster_.queue->stored();
  return stored.ok() && *stored >= queue_capacity_;
}

absl::StatusOr<uint32_t> ClusterJobStore::accept(v1::JobRecord record,
                                                 const std::string& upload_path) {
  const std::string id = record.job().job_id();
  std::error_code error;
  auto existing = cluster_.jobs->get(id);
  if (existing.ok()) {
    // A retry that raced its first try here: the job exists already.
    fs::remove(upload_path, error);
    if (existing->deleted()) {
      return absl::AbortedError(
          "the job of this request_id is being deleted; retry once it is gone");
    }
    return 0;
  }
  if (existing.status().code() != absl::StatusCode::kNotFound) return existing.status();
  record.mutable_job()->set_state(v1::JOB_STATE_QUEUED);
  LABELMESH_RETURN_IF_ERROR(
      files_.put(absl::StrCat("jobs/", id, "/job.pb"), record.SerializeAsString()));
  fs::rename(upload_path, absl::StrCat(files_.job_dir(id), "/input", record.input_extension()),
             error);
  if (error) return spool_io_error("cannot move the upload into its job", error.value());
  auto submitted = cluster_.jobs->submit(std::move(record));
  if (!submitted.ok()) {
    // Its files go unless another frontend recorded the job meanwhile.
    if (cluster_.jobs->get(id).status().code() == absl::StatusCode::kNotFound)
      files_.remove_job(id);
    return submitted.status();
  }
  spdlog::info("job {} queued", id);
  auto stored = cluster_.queue->stored();
  return stored.ok() && *stored > 0 ? static_cast<uint32_t>(*stored - 1) : 0;
}

absl::StatusOr<v1::JobRecord> ClusterJobStore::record(const std::string& job_id) const {
  auto record = cluster_.jobs->get(job_id);
  if (!record.ok() && record.status().code() == absl::StatusCode::kNotFound)
    return absl::NotFoundError(absl::StrCat("no job ", job_id));
  if (record.ok() && record->deleted()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return record;
}

absl::StatusOr<v1::Job> ClusterJobStore::get(const std::string& job_id) const {
  LABELMESH_ASSIGN_OR_RETURN(auto found, record(job_id));
  v1::Job job = found.job();
  if (job.state() == v1::JOB_STATE_RUNNING) {
    // The record holds no stage: the newest event tells it.
    auto last = cluster_.events->last(job_id);
    v1::JobEvent event;
    if (last.ok() && last->has_value() && event.ParseFromString(**last)) {
      if (event.has_stage_started()) job.set_stage(event.stage_started().stage());
      if (event.has_progress()) {
        job.set_stage(event.progress().stage());
        job.set_progress(event.progress().fraction());
      }
      if (event.has_stage_finished()) job.set_stage(event.stage_finished().stage());
    }
  }
  return with_timestamps(std::move(job));
}

absl::StatusOr<std::string> ClusterJobStore::owner(const std::string& job_id) const {
  LABELMESH_ASSIGN_OR_RETURN(auto found, record(job_id));
  return found.job().owner();
}

absl::StatusOr<JobStore::JobPage> ClusterJobStore::list(const JobQuery& query) const {
  LABELMESH_ASSIGN_OR_RETURN(auto ids, cluster_.jobs->job_ids());
  std::vector<v1::Job> jobs;
  for (const auto& id : ids) {
    auto found = record(id);
    if (found.status().code() == absl::StatusCode::kNotFound) continue;  // deleted meanwhile
    if (!found.ok()) return found.status();
    if (!query.owner.empty() && found->job().owner() != query.owner) continue;
    jobs.push_back(with_timestamps(found->job()));
  }
  return page_of(std::move(jobs), query);
}

std::optional<JobStore::PriorRequest> ClusterJobStore::find_request(
    const std::string& owner, const std::string& request_id) const {
  const std::string id = job_id_of_request(owner, request_id);
  auto found = record(id);
  if (!found.ok()) return std::nullopt;
  return PriorRequest{id, found->spec().sha256(), 0};
}

absl::Status ClusterJobStore::erase(const std::string& job_id) const {
  files_.remove_job(job_id);
  return cluster_.jobs->erase(job_id);
}

absl::StatusOr<v1::JobState> ClusterJobStore::remove(const std::string& job_id) {
  LABELMESH_ASSIGN_OR_RETURN(auto found, record(job_id));
  LABELMESH_ASSIGN_OR_RETURN(auto removed, cluster_.jobs->remove(job_id));
  // A running job's worker removes its files once it stops.
  if (removed) files_.remove_job(job_id);
  spdlog::info("job {} deleted by a client", job_id);
  return found.job().state();
}

absl::StatusOr<v1::Job> ClusterJobStore::cancel(const std::string& job_id) {
  LABELMESH_RETURN_IF_ERROR(record(job_id));
  LABELMESH_ASSIGN_OR_RETURN(auto cancelled, cluster_.jobs->cancel(job_id));
  return with_timestamps(cancelled.job());
}

absl::StatusOr<std::vector<v1::Artifact>> ClusterJobStore::artifacts(
    const std::string& job_id) const {
  LABELMESH_ASSIGN_OR_RETURN(auto found, record(job_id));
  if (found.job().state() != v1::JOB_STATE_SUCCEEDED) {
    return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " has no results: it is ",
                                                      v1::JobState_Name(found.job().state())));
  }
  return std::vector<v1::Artifact>(found.artifacts().begin(), found.artifacts().end());
}

std::string ClusterJobStore::artifact_path(const v1::Job& job, const std::string& name) const {
  return absl::StrCat(files_.attempt_dir(job.job_id(), job.attempts()), "/", name);
}

absl::Status ClusterJobStore::replay_ended(const v1::JobRecord& record, uint64_t from,
                                           EventListener* listener) {
  LABELMESH_ASSIGN_OR_RETURN(auto follower, cluster_.events->follow(record.job().job_id(), from));
  for (;;) {
    LABELMESH_ASSIGN_OR_RETURN(auto next, (follower)->next(kReplayWait));
    if (!next.has_value()) break;
    const v1::JobEvent event = watched_event(*next);
    const bool last = is_last(event);
    listener->on_event(event, last);
    if (last) return absl::OkStatus();
  }
  // Its end was not logged (a worker died between the two writes) or has
  // aged out of the log: the record tells it.
  if (from == 0) {
    listener->on_event(state_event(record.job(), 0), true);
  } else {
    listener->on_closed(absl::OkStatus());
  }
  return absl::OkStatus();
}

absl::Status ClusterJobStore::listen(const std::string& job_id, uint64_t from,
                                     EventListener* listener) {
  {
    absl::MutexLock lock(&mutex_);
    if (closed_) return absl::UnavailableError("the server is shutting down");
  }
  LABELMESH_ASSIGN_OR_RETURN(auto found, record(job_id));
  if (has_ended(found.job().state())) return replay_ended(found, from, listener);
  auto heard_last = std::make_shared<std::atomic<bool>>(false);
  auto subscription =
      cluster_.events->subscribe(job_id, from, [listener, heard_last](cluster::LoggedEvent logged) {
        const v1::JobEvent event = watched_event(logged);
        const bool last = is_last(event);
        listener->on_event(event, last);
        if (last) *heard_last = true;
      });
  if (!subscription.ok()) return subscription.status();
  {
    absl::MutexLock lock(&mutex_);
    if (!closed_) {
      follows_[listener] = Follow{job_id, std::move(*subscription), heard_last};
      return absl::OkStatus();
    }
  }
  subscription->reset();
  return absl::UnavailableError("the server is shutting down");
}

void ClusterJobStore::unlisten(const std::string&, EventListener* listener) {
  Follow follow;
  {
    absl::MutexLock lock(&mutex_);
    // A listener being told its end is not gone until it has been told.
    const auto told = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) {
      return !ending_.contains(listener);
    };
    mutex_.Await(absl::Condition(&told));
    auto it = follows_.find(listener);
    if (it == follows_.end()) return;
    follow = std::move(it->second);
    follows_.erase(it);
  }
  // Destroyed outside the lock: it waits for a callback in progress.
  follow.subscription.reset();
}

void ClusterJobStore::end_follows(std::vector<Ending> endings) {
  for (auto& ending : endings) {
    ending.follow.subscription.reset();  // no event after this
    // A listener handed its last event meanwhile has heard the end.
    if (!*ending.follow.heard_last) {
      if (ending.last_event) {
        ending.listener->on_event(*ending.last_event, true);
      } else {
        ending.listener->on_closed(ending.status);
      }
    }
    absl::MutexLock lock(&mutex_);
    ending_.erase(ending.listener);
  }
}

void ClusterJobStore::check_follows() {
  // Job ids read under the lock, records without it (NATS calls).
  std::vector<std::pair<EventListener*, std::string>> watched;
  {
    absl::MutexLock lock(&mutex_);
    for (const auto& [listener, follow] : follows_) {
      if (!*follow.heard_last) watched.emplace_back(listener, follow.job_id);
    }
  }
  std::map<EventListener*, std::pair<std::string, absl::StatusOr<v1::JobRecord>>> records;
  for (const auto& [listener, job_id] : watched)
    records.emplace(listener, std::make_pair(job_id, record(job_id)));
  const double now = unix_now();
  std::vector<Ending> endings;
  {
    absl::MutexLock lock(&mutex_);
    for (auto& [listener, checked] : records) {
      auto& [job_id, found] = checked;
      auto it = follows_.find(listener);
      // Gone, or a new listener at the same address following another job.
      if (it == follows_.end() || it->second.job_id != job_id || *it->second.heard_last) continue;
      Follow& follow = it->second;
      std::optional<v1::JobEvent> last_event;
      absl::Status status;
      if (found.status().code() == absl::StatusCode::kNotFound) {
        status = absl::NotFoundError(absl::StrCat("job ", follow.job_id, " was deleted"));
      } else if (found.ok() && has_ended(found->job().state())) {
        if (follow.ended_seen == 0) follow.ended_seen = now;
        if (now - follow.ended_seen < absl::ToDoubleSeconds(kLastEventWait)) continue;
        last_event = state_event(found->job(), 0);
      } else {
        continue;
      }
      ending_.insert(listener);
      endings.push_back({listener, std::move(follow), status, std::move(last_event)});
      follows_.erase(it);
    }
  }
  end_follows(std::move(endings));
}

std::vector<std::string> ClusterJobStore::expire(absl::Duration result_ttl, size_t max_ended) {
  std::vector<std::string> removed;
  auto ids = cluster_.jobs->job_ids();
  if (!ids.ok()) return removed;
  const double cutoff = unix_now() - absl::ToDoubleSeconds(result_ttl);
  const double abandoned = unix_now() - absl::ToDoubleSeconds(abandoned_after_);
  std::vector<std::pair<double, std::string>> ended;
  for (const auto& id : *ids) {
    auto found = cluster_.jobs->get(id);
    if (!found.ok()) continue;
    if (has_ended(found->job().state())) ended.emplace_back(found->job().finished_at(), id);
    if (found->job().state() == v1::JOB_STATE_RUNNING && found->job().started_at() < abandoned) {
      if (auto gave_up = cluster_.jobs->give_up(id, abandoned); gave_up.ok() && *gave_up) {
        spdlog::warn("job {} lost its workers past the job timeout: failed", id);
        // Deleted by a client while it ran: nobody else will remove it.
        if (found->deleted()) (void)erase(id);
      }
    }
  }
  std::sort(ended.begin(), ended.end());
  const size_t over_cap = ended.size() > max_ended ? ended.size() - max_ended : 0;
  for (size_t i = 0; i < ended.size(); ++i) {
    const auto& [finished_at, id] = ended[i];
    if (finished_at >= cutoff && i >= over_cap) continue;
    if (!erase(id).ok()) continue;
    spdlog::info("job {} results expired and deleted", id);
    removed.push_back(id);
  }
  return removed;
}

size_t ClusterJobStore::remove_abandoned_uploads(absl::Duration age) const {
  const auto cutoff = fs::file_time_type::clock::now() - absl::ToChronoSeconds(age);
  size_t removed = 0;
  std::error_code error;
  // Without exceptions: a shared folder can fail a read (ESTALE on NFS).
  for (fs::directory_iterator it(files_.root() + "/uploads", error), end; !error && it != end;
       it.increment(error)) {
    std::error_code ignored;
    const auto& entry = *it;
    if (entry.is_regular_file(ignored) && entry.last_write_time(ignored) < cutoff &&
        fs::remove(entry.path(), ignored))
      ++removed;
  }
  return removed;
}

void ClusterJobStore::close() {
  std::vector<Ending> endings;
  {
    absl::MutexLock lock(&mutex_);
    closed_ = true;
    const absl::Status closing = absl::UnavailableError("the server is shutting down");
    for (auto& [listener, follow] : follows_) {
      ending_.insert(listener);
      endings.push_back({listener, std::move(follow), closing, std::nullopt});
    }
    follows_.clear();
  }
  end_follows(std::move(endings));
}

}  // namespace labelmesh::server
