// SPDX-License-Identifier: AGPL-3.0-or-later
// One Watch stream on gRPC's callback API: the job store hands it each event
// as it is added and the reactor writes them in order, so a watcher waiting
// for news holds no thread. A watcher that stops reading is cancelled by the
// stream watchdog once a write has been outstanding for the idle timeout.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <deque>
#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "labelmesh/v1/service.pb.h"
#include "server/job_store.h"
#include "server/stream_limits.h"

namespace labelmesh::server {

class WatchReactor final : public grpc::ServerWriteReactor<v1::JobEvent>,
                           private JobStore::EventListener {
 public:
  // Starts streaming the job's events; the reactor deletes itself when gRPC
  // is done with it. `slot` holds the stream's place among the client's.
  static WatchReactor* start(JobStore& store, StreamWatchdog& watchdog, absl::Duration idle_timeout,
                             grpc::CallbackServerContext* context, std::string job_id,
                             std::unique_ptr<StreamCounts::Slot> slot);

 private:
  WatchReactor(JobStore& store, std::string job_id, std::unique_ptr<StreamCounts::Slot> slot);

  void on_event(const v1::JobEvent& event, bool last) override;
  void on_closed(const absl::Status& status) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

  // Starts the next write, or finishes the stream when nothing is left to
  // write and the end has come.
  void write_next() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  void finish(const grpc::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  grpc::Status left_or_stalled() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);

  JobStore& store_;
  const std::string job_id_;
  std::unique_ptr<StreamCounts::Slot> slot_;
  // When the outstanding write started (ns since the epoch), 0 when none:
  // what the watchdog reads, without a lock.
  std::atomic<int64_t> write_started_{0};
  // Declared after what it reads, so that it goes first.
  std::unique_ptr<StreamWatchdog::Ticket> ticket_;

  absl::Mutex mutex_;
  bool listening_ ABSL_GUARDED_BY(mutex_) = false;
  // Until start() has recorded whether it listens: a finish waits for it.
  bool starting_ ABSL_GUARDED_BY(mutex_) = true;
  bool finish_deferred_ ABSL_GUARDED_BY(mutex_) = false;
  grpc::Status deferred_status_ ABSL_GUARDED_BY(mutex_);
  std::deque<v1::JobEvent> pending_ ABSL_GUARDED_BY(mutex_);
  v1::JobEvent writing_ ABSL_GUARDED_BY(mutex_);
  bool write_outstanding_ ABSL_GUARDED_BY(mutex_) = false;
  bool end_queued_ ABSL_GUARDED_BY(mutex_) = false;
  grpc::Status end_status_ ABSL_GUARDED_BY(mutex_);
  bool cancelled_ ABSL_GUARDED_BY(mutex_) = false;
  bool finished_ ABSL_GUARDED_BY(mutex_) = false;
};

}  // namespace labelmesh::server
