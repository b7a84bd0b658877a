// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/job_table.h"

#include "core/util/status_macros.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "server/client_identity.h"
#include "server/refusal.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace {

// Watchers of a long job see every stage event; progress events past this
// many are applied to the job but not kept.
constexpr size_t kMaxStoredEvents = 4096;

}  // namespace

JobTable::JobTable(const Spool& spool, int queue_capacity, Metrics& metrics)
    : spool_(spool),
      queue_capacity_(static_cast<size_t>(queue_capacity)),
      metrics_(metrics),
      // Microseconds since 1970: sequences keep growing across restarts, so a
      // watcher that reconnects can tell new events from replayed ones.
      next_sequence_(static_cast<uint64_t>(unix_now() * 1e6)) {}

JobTable::Entry* JobTable::find(const std::string& job_id) {
  auto it = jobs_.find(job_id);
  return it == jobs_.end() ? nullptr : &it->second;
}

const JobTable::Entry* JobTable::find_visible(const std::string& job_id) const {
  const Entry* entry = find(job_id);
  return entry == nullptr || entry->remove_when_ended ? nullptr : entry;
}

JobTable::Entry* JobTable::find_visible(const std::string& job_id) {
  Entry* entry = find(job_id);
  return entry == nullptr || entry->remove_when_ended ? nullptr : entry;
}

const JobTable::Entry* JobTable::find(const std::string& job_id) const {
  auto it = jobs_.find(job_id);
  return it == jobs_.end() ? nullptr : &it->second;
}

absl::Status JobTable::persist(const v1::JobRecord& record) {
  absl::Status status = spool_.save(record);
  if (!status.ok()) {
    metrics_.spool_write_failed();
    spdlog::error("job {} record not saved: {}", record.job().job_id(),
                  std::string(status.message()));
  }
  return status;
}

void JobTable::update_gauges() {
  metrics_.set_queue_depth(queue_.size());
  metrics_.set_running(running_);
}

uint32_t JobTable::position_of(const std::string& job_id) const {
  auto it = std::find(queue_.begin(), queue_.end(), job_id);
  return static_cast<uint32_t>(it - queue_.begin());
}

void JobTable::add_event(Entry& entry, v1::JobEvent event) {
  event.set_job_id(entry.record.job().job_id());
  event.set_sequence(next_sequence_++);
  event.set_time(unix_now());
  *event.mutable_timestamp() = to_timestamp(event.time());
  if (event.has_progress() && entry.events.size() >= kMaxStoredEvents) return;
  entry.events.push_back(std::move(event));
  const bool last = has_ended(entry.record.job().state());
  for (EventListener* listener : entry.listeners) listener->on_event(entry.events.back(), last);
  if (last) entry.listeners.clear();
}

void JobTable::recover(absl::Duration result_ttl) {
  std::vector<v1::JobRecord> records = spool_.load_all();
  std::sort(records.begin(), records.end(), [](const auto& a, const auto& b) {
    return a.job().created_at() < b.job().created_at();
  });
  const double now = unix_now();
  absl::MutexLock lock(&mutex_);
  int requeued = 0, kept = 0, expired = 0;
  for (auto& record : records) {
    v1::Job& job = *record.mutable_job();
    const std::string id = job.job_id();
    if (record.deleted()) {  // deleted by a client while it ran
      spool_.remove_job(id);
      continue;
    }
    // Results from before attempts had directories of their own.
    if (job.state() == v1::JOB_STATE_SUCCEEDED) spool_.adopt_output(id, job.attempts());
    // Jobs from before identities belong to the anonymous client: every
    // caller of a server without authentication, only admins otherwise.
    if (job.owner().empty()) job.set_owner(kAnonymous);
    if (has_ended(job.state())) {
      if (job.finished_at() + absl::ToDoubleSeconds(result_ttl) < now) {
        spool_.remove_job(id);
        ++expired;
        continue;
      }
      // Ended before its input was deleted (a crash in between).
      if (!record.spec().keep_input()) spool_.remove_input(record);
      ++kept;
    } else {
      // Queued, or running when the server stopped: runs again from the start.
      job.set_state(v1::JOB_STATE_QUEUED);
      job.clear_stage();
      job.set_progress(0);
      queue_.push_back(id);
      ++requeued;
    }
    Entry& entry = jobs_[id];
    entry.record = std::move(record);
    if (!has_ended(entry.record.job().state())) (void)persist(entry.record);
    add_event(entry, state_event(entry.record.job(), position_of(id)));
  }
  update_gauges();
  spdlog::info("spool: {} jobs queued again, {} ended jobs kept, {} expired jobs deleted", requeued,
               kept, expired);
}

bool JobTable::ready_to_dispatch() const { return closed_ || (dispatching_ && !queue_.empty()); }

bool JobTable::queue_full() const {
  absl::MutexLock lock(&mutex_);
  return queue_.size() >= queue_capacity_;
}

absl::StatusOr<uint32_t> JobTable::accept(v1::JobRecord record, const std::string& upload_path) {
  absl::MutexLock lock(&mutex_);
  if (closed_) return absl::UnavailableError("the server is shutting down");
  if (queue_.size() >= queue_capacity_) {
    return refused(Refusal::kQueueFull,
                   absl::ResourceExhaustedError(absl::StrCat(
                       "the job queue is full (", queue_capacity_, " jobs); try again later")));
  }
  const std::string id = record.job().job_id();
  record.mutable_job()->set_state(v1::JOB_STATE_QUEUED);
  LABELMESH_RETURN_IF_ERROR(spool_.create_job(record, upload_path));
  Entry& entry = jobs_[id];
  entry.record = std::move(record);
  queue_.push_back(id);
  const uint32_t position = position_of(id);
  v1::JobEvent event;
  event.mutable_queued()->set_position(position);
  add_event(entry, std::move(event));
  update_gauges();
  spdlog::info("job {} queued at position {}", id, position);
  return position;
}

std::optional<v1::JobRecord> JobTable::take_next() {
  absl::MutexLock lock(&mutex_);
  mutex_.Await(absl::Condition(this, &JobTable::ready_to_dispatch));
  if (closed_) return std::nullopt;
  const std::string id = queue_.front();
  queue_.pop_front();
  Entry& entry = *find(id);
  v1::Job& job = *entry.record.mutable_job();
  const double now = unix_now();
  if (job.attempts() == 0) metrics_.queue_wait(now - job.created_at());
  job.set_state(v1::JOB_STATE_RUNNING);
  job.set_attempts(job.attempts() + 1);
  job.set_started_at(now);
  // Unsaved, the job still runs; on disk it stays queued and runs again
  // after a restart.
  (void)persist(entry.record);
  ++running_;
  v1::JobEvent event;
  event.mutable_started()->set_attempt(job.attempts());
  add_event(entry, std::move(event));
  update_gauges();
  spdlog::info("job {} started (attempt {})", id, job.attempts());
  return entry.record;
}

void JobTable::publish(const std::string& job_id, v1::JobEvent event) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr || entry->record.job().state() != v1::JOB_STATE_RUNNING) return;
  v1::Job& job = *entry->record.mutable_job();
  if (event.has_stage_started()) {
    job.set_stage(event.stage_started().stage());
    job.set_progress(0);
  } else if (event.has_progress()) {
    job.set_stage(event.progress().stage());
    job.set_progress(event.progress().fraction());
  } else if (event.has_stage_finished()) {
    const auto& finished = event.stage_finished();
    metrics_.stage_finished(finished.stage(), finished.seconds());
    spdlog::info("job {} stage {} finished in {:.3f} s", job_id, finished.stage(),
                 finished.seconds());
  } else {
    return;  // Ends go through succeed, fail and mark_cancelled.
  }
  add_event(*entry, std::move(event));
}

absl::Status JobTable::end_job(Entry& entry, v1::JobState state, v1::JobEvent event,
                               Unsaved unsaved, const v1::JobError* error) {
  v1::JobRecord ended = entry.record;
  v1::Job& job = *ended.mutable_job();
  if (error != nullptr) *job.mutable_error() = *error;
  const bool was_running = job.state() == v1::JOB_STATE_RUNNING;
  job.set_state(state);
  job.set_finished_at(unix_now());
  job.clear_stage();
  const absl::Status saved = persist(ended);
  if (!saved.ok() && unsaved == Unsaved::kRefuse) return saved;
  // Unsaved, the job runs again after a restart and needs its input.
  if (saved.ok() && !ended.spec().keep_input()) spool_.remove_input(ended);
  entry.record = std::move(ended);
  if (was_running && running_ > 0) --running_;
  add_event(entry, std::move(event));
  update_gauges();
  static const char* const kOutcome[] = {"", "", "", "succeeded", "failed", "cancelled"};
  metrics_.job_ended(kOutcome[state]);
  return absl::OkStatus();
}

void JobTable::succeed(const std::string& job_id, const v1::Report& report,
                       std::vector<v1::Artifact> artifacts) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr) return;
  *entry->record.mutable_job()->mutable_report() = report;
  entry->record.mutable_job()->set_progress(1);
  entry->record.clear_artifacts();
  for (auto& artifact : artifacts) *entry->record.add_artifacts() = std::move(artifact);
  v1::JobEvent event;
  *event.mutable_finished()->mutable_report() = report;
  (void)end_job(*entry, v1::JOB_STATE_SUCCEEDED, std::move(event), Unsaved::kApply);
  spdlog::info("job {} succeeded in {:.3f} s", job_id,
               entry->record.job().finished_at() - entry->record.job().started_at());
  remove_if_requested(job_id);
}

void JobTable::fail(const std::string& job_id, int code, const std::string& message) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr) return;
  v1::JobError& error = *entry->record.mutable_job()->mutable_error();
  error.set_code(code);
  error.set_message(message);
  v1::JobEvent event;
  *event.mutable_failed() = error;
  (void)end_job(*entry, v1::JOB_STATE_FAILED, std::move(event), Unsaved::kApply);
  // The message may quote the volume's fields; the log keeps the code only.
  spdlog::warn("job {} failed with status code {}", job_id, code);
  remove_if_requested(job_id);
}

absl::Status JobTable::end_cancelled(Entry& entry, Unsaved unsaved) {
  v1::JobError error;
  error.set_code(static_cast<int>(absl::StatusCode::kCancelled));
  error.set_message("cancelled by a client");
  v1::JobEvent event;
  event.mutable_cancelled();
  LABELMESH_RETURN_IF_ERROR(
      end_job(entry, v1::JOB_STATE_CANCELLED, std::move(event), unsaved, &error));
  spdlog::info("job {} cancelled", entry.record.job().job_id());
  return absl::OkStatus();
}

void JobTable::mark_cancelled(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr || has_ended(entry->record.job().state())) return;
  (void)end_cancelled(*entry, Unsaved::kApply);
  remove_if_requested(job_id);
}

bool JobTable::remove_if_requested(const std::string& job_id) {
  Entry* entry = find(job_id);
  if (entry == nullptr || !entry->remove_when_ended) return false;
  spool_.remove_job(job_id);
  erase_entry(job_id);
  spdlog::info("job {} deleted by a client once its worker stopped", job_id);
  return true;
}

void JobTable::requeue_interrupted(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr || entry->record.job().state() != v1::JOB_STATE_RUNNING) return;
  if (entry->remove_when_ended) {
    if (running_ > 0) --running_;
    update_gauges();
    remove_if_requested(job_id);
    return;
  }
  entry->record.mutable_job()->set_state(v1::JOB_STATE_QUEUED);
  (void)persist(entry->record);
  if (running_ > 0) --running_;
  update_gauges();
  spdlog::info("job {} interrupted by shutdown; it runs again at the next start", job_id);
}

void JobTable::give_back(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find(job_id);
  if (entry == nullptr || entry->record.job().state() != v1::JOB_STATE_RUNNING) return;
  // A cancel (or delete) that came while it was taken ends it now.
  if (entry->cancel_requested) {
    (void)end_cancelled(*entry, Unsaved::kApply);
    remove_if_requested(job_id);
    return;
  }
  if (running_ > 0) --running_;
  if (entry->remove_when_ended) {
    update_gauges();
    remove_if_requested(job_id);
    return;
  }
  v1::Job& job = *entry->record.mutable_job();
  job.set_state(v1::JOB_STATE_QUEUED);
  job.set_attempts(job.attempts() - 1);
  job.set_started_at(0);
  job.clear_stage();
  (void)persist(entry->record);
  queue_.push_front(job_id);
  v1::JobEvent event;
  event.mutable_queued()->set_position(0);  // next
  add_event(*entry, std::move(event));
  update_gauges();
  spdlog::info("job {} given back to the queue: no room for its results", job_id);
}

bool JobTable::dispatching() const {
  absl::MutexLock lock(&mutex_);
  return dispatching_ && !closed_;
}

v1::Job JobTable::view(const std::string& job_id, const v1::Job& stored) const {
  v1::Job job = with_timestamps(stored);
  if (job.state() == v1::JOB_STATE_QUEUED) job.set_queue_position(position_of(job_id));
  return job;
}

absl::StatusOr<v1::Job> JobTable::get(const std::string& job_id) const {
  absl::MutexLock lock(&mutex_);
  const Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return view(job_id, entry->record.job());
}

absl::StatusOr<std::string> JobTable::owner(const std::string& job_id) const {
  absl::MutexLock lock(&mutex_);
  const Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return entry->record.job().owner();
}

absl::StatusOr<JobTable::JobPage> JobTable::list(const JobQuery& query) const {
  std::vector<v1::Job> jobs;
  {
    absl::MutexLock lock(&mutex_);
    for (const auto& [id, entry] : jobs_) {
      if (entry.remove_when_ended) continue;
      if (!query.owner.empty() && entry.record.job().owner() != query.owner) continue;
      jobs.push_back(view(id, entry.record.job()));
    }
  }
  return page_of(std::move(jobs), query);
}

std::string JobTable::new_job_id_for(const std::string&, const std::string&) {
  return new_job_id();
}

std::string JobTable::upload_path(const std::string& job_id, const std::string& extension) {
  return spool_.upload_path(job_id, extension);
}

absl::StatusOr<uint64_t> JobTable::free_bytes() const { return spool_.free_bytes(); }

std::string JobTable::artifact_path(const v1::Job& job, const std::string& name) const {
  return absl::StrCat(spool_.output_dir(job.job_id(), job.attempts()), "/", name);
}

std::optional<JobTable::PriorRequest> JobTable::find_request(const std::string& owner,
                                                             const std::string& request_id) const {
  absl::MutexLock lock(&mutex_);
  for (const auto& [id, entry] : jobs_) {
    const v1::JobRecord& record = entry.record;
    if (entry.remove_when_ended || record.spec().request_id() != request_id ||
        record.job().owner() != owner)
      continue;
    const bool queued = record.job().state() == v1::JOB_STATE_QUEUED;
    return PriorRequest{id, record.spec().sha256(), queued ? position_of(id) : 0};
  }
  return std::nullopt;
}

absl::StatusOr<v1::JobState> JobTable::remove(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const v1::JobState state = entry->record.job().state();
  if (state == v1::JOB_STATE_RUNNING) {
    // The worker still writes in the job's directory: it goes when it stops.
    // The record says so first, so that a restart meanwhile deletes it too.
    v1::JobRecord deleted = entry->record;
    deleted.set_deleted(true);
    LABELMESH_RETURN_IF_ERROR(persist(deleted));
    entry->record = std::move(deleted);
    entry->cancel_requested = true;
    entry->remove_when_ended = true;
    return state;
  }
  if (auto it = std::find(queue_.begin(), queue_.end(), job_id); it != queue_.end()) {
    queue_.erase(it);
    update_gauges();
  }
  spool_.remove_job(job_id);
  erase_entry(job_id);
  spdlog::info("job {} deleted by a client", job_id);
  return state;
}

absl::StatusOr<v1::Job> JobTable::cancel(const std::string& job_id) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const v1::JobState state = entry->record.job().state();
  if (has_ended(state)) {
    return absl::FailedPreconditionError(
        absl::StrCat("job ", job_id, " already ended (", v1::JobState_Name(state), ")"));
  }
  if (state == v1::JOB_STATE_RUNNING) {
    entry->cancel_requested = true;
  } else {
    // The client hears "cancelled" only once the record says so on disk.
    LABELMESH_RETURN_IF_ERROR(end_cancelled(*entry, Unsaved::kRefuse));
    if (auto it = std::find(queue_.begin(), queue_.end(), job_id); it != queue_.end())
      queue_.erase(it);
    update_gauges();
  }
  return view(job_id, entry->record.job());
}

bool JobTable::cancel_requested(const std::string& job_id) const {
  absl::MutexLock lock(&mutex_);
  const Entry* entry = find(job_id);
  return entry != nullptr && entry->cancel_requested;
}

absl::StatusOr<std::vector<v1::Artifact>> JobTable::artifacts(const std::string& job_id) const {
  absl::MutexLock lock(&mutex_);
  const Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  if (entry->record.job().state() != v1::JOB_STATE_SUCCEEDED) {
    return absl::FailedPreconditionError(absl::StrCat(
        "job ", job_id, " has no results: it is ", v1::JobState_Name(entry->record.job().state())));
  }
  return std::vector<v1::Artifact>(entry->record.artifacts().begin(),
                                   entry->record.artifacts().end());
}

std::vector<std::string> JobTable::expire(absl::Duration result_ttl, size_t max_ended) {
  absl::MutexLock lock(&mutex_);
  const double cutoff = unix_now() - absl::ToDoubleSeconds(result_ttl);
  // Ended jobs, oldest end first: past the TTL, or past the cap in number.
  std::vector<std::pair<double, std::string>> ended;
  for (const auto& [id, entry] : jobs_) {
    const v1::Job& job = entry.record.job();
    if (has_ended(job.state())) ended.emplace_back(job.finished_at(), id);
  }
  std::sort(ended.begin(), ended.end());
  const size_t over_cap = ended.size() > max_ended ? ended.size() - max_ended : 0;
  std::vector<std::string> removed;
  for (size_t i = 0; i < ended.size(); ++i) {
    const auto& [finished_at, id] = ended[i];
    const bool expired = finished_at < cutoff;
    if (!expired && i >= over_cap) continue;
    spool_.remove_job(id);
    spdlog::info("job {} results {} and deleted", id,
                 expired ? "expired" : "past the cap on ended jobs");
    removed.push_back(id);
    erase_entry(id);
  }
  return removed;
}

void JobTable::erase_entry(const std::string& job_id) {
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return;
  const absl::Status gone = absl::NotFoundError(absl::StrCat("job ", job_id, " was deleted"));
  for (EventListener* listener : it->second.listeners) listener->on_closed(gone);
  jobs_.erase(it);
}

absl::Status JobTable::listen(const std::string& job_id, uint64_t from, EventListener* listener) {
  absl::MutexLock lock(&mutex_);
  Entry* entry = find_visible(job_id);
  if (entry == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const bool ended = has_ended(entry->record.job().state());
  if (closed_ && !ended) return absl::UnavailableError("the server is shutting down");
  bool replayed_last = false;
  for (size_t i = 0; i < entry->events.size(); ++i) {
    if (entry->events[i].sequence() < from) continue;
    replayed_last = ended && i + 1 == entry->events.size();
    listener->on_event(entry->events[i], replayed_last);
  }
  if (!ended) {
    entry->listeners.push_back(listener);
  } else if (!replayed_last) {
    listener->on_closed(absl::OkStatus());
  }
  return absl::OkStatus();
}

void JobTable::unlisten(const std::string& job_id, EventListener* listener) {
  absl::MutexLock lock(&mutex_);
  if (Entry* entry = find(job_id)) std::erase(entry->listeners, listener);
}

void JobTable::close() {
  absl::MutexLock lock(&mutex_);
  closed_ = true;
  const absl::Status closing = absl::UnavailableError("the server is shutting down");
  for (auto& [id, entry] : jobs_) {
    for (EventListener* listener : entry.listeners) listener->on_closed(closing);
    entry.listeners.clear();
  }
}

void JobTable::stop_dispatch() {
  absl::MutexLock lock(&mutex_);
  dispatching_ = false;
}

}  // namespace labelmesh::server
