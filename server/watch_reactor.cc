// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/watch_reactor.h"

#include "absl/time/clock.h"
#include "server/error_details.h"

namespace labelmesh::server {

WatchReactor* WatchReactor::start(JobStore& store, StreamWatchdog& watchdog,
                                  absl::Duration idle_timeout, grpc::CallbackServerContext* context,
                                  std::string job_id, std::unique_ptr<StreamCounts::Slot> slot) {
  auto* reactor = new WatchReactor(store, std::move(job_id), std::move(slot));
  reactor->ticket_ = watchdog.watch_writes(
      context, idle_timeout, [reactor] { return reactor->write_started_.load(); }, "watch");
  // Replays what happened so far, then follows; events may arrive at once.
  const absl::Status listening = store.listen(reactor->job_id_, 0, reactor);
  absl::MutexLock lock(&reactor->mutex_);
  reactor->listening_ = listening.ok();
  if (!listening.ok()) reactor->finish(to_grpc(listening));
  // An end that came while listen() ran (events may come on another
  // thread) finishes the stream only now, so that OnDone knows to unlisten.
  reactor->starting_ = false;
  if (reactor->finish_deferred_) reactor->Finish(reactor->deferred_status_);
  return reactor;
}

WatchReactor::WatchReactor(JobStore& store, std::string job_id,
                           std::unique_ptr<StreamCounts::Slot> slot)
    : store_(store), job_id_(std::move(job_id)), slot_(std::move(slot)) {}

void WatchReactor::on_event(const v1::JobEvent& event, bool last) {
  absl::MutexLock lock(&mutex_);
  if (finished_ || end_queued_) return;  // nothing follows a job's end
  pending_.push_back(event);
  if (last) {
    end_queued_ = true;
    end_status_ = grpc::Status::OK;
  }
  write_next();
}

void WatchReactor::on_closed(const absl::Status& status) {
  absl::MutexLock lock(&mutex_);
  if (finished_ || end_queued_) return;
  end_queued_ = true;
  end_status_ = to_grpc(status);
  write_next();
}

void WatchReactor::write_next() {
  if (finished_ || write_outstanding_) return;
  if (cancelled_) return finish(left_or_stalled());
  if (!pending_.empty()) {
    writing_ = std::move(pending_.front());
    pending_.pop_front();
    write_outstanding_ = true;
    write_started_ = absl::ToUnixNanos(absl::Now());
    StartWrite(&writing_);
    return;
  }
  if (end_queued_) finish(end_status_);
}

void WatchReactor::OnWriteDone(bool ok) {
  absl::MutexLock lock(&mutex_);
  write_outstanding_ = false;
  write_started_ = 0;
  if (!ok) cancelled_ = true;
  write_next();
}

void WatchReactor::OnCancel() {
  absl::MutexLock lock(&mutex_);
  cancelled_ = true;
  // An outstanding write completes (not ok) and finishes the stream then.
  write_next();
}

grpc::Status WatchReactor::left_or_stalled() const {
  const absl::Status left = absl::CancelledError("watcher left");
  return to_grpc(ticket_ ? ticket_->cancellation_or(left) : left);
}

void WatchReactor::finish(const grpc::Status& status) {
  if (finished_) return;
  finished_ = true;
  if (starting_) {
    finish_deferred_ = true;
    deferred_status_ = status;
    return;
  }
  Finish(status);
}

void WatchReactor::OnDone() {
  bool listening = false;
  {
    absl::MutexLock lock(&mutex_);
    listening = listening_;
  }
  // After unlisten returns, the store never calls this reactor again.
  if (listening) store_.unlisten(job_id_, this);
  delete this;
}

}  // namespace labelmesh::server
