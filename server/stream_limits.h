// SPDX-License-Identifier: AGPL-3.0-or-later
// What one client can hold of the server: streams open at once, per client
// and in all, and how long a stream may stall. A stalled stream (an upload
// whose next chunk does not come, a fetch or watch whose reader stopped
// reading) is cancelled, which frees its thread and its upload slot.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace labelmesh::server {

// The client part of a gRPC peer ("ipv4:10.0.0.7:53211" -> "ipv4:10.0.0.7").
std::string peer_host(const std::string& peer);

// Counts the streams each client (peer host) and all clients hold open.
class StreamCounts {
 public:
  StreamCounts(int per_client, int total) : per_client_(per_client), total_(total) {}

  // Holds one stream's place until destroyed.
  class Slot {
   public:
    ~Slot();
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;

   private:
    friend class StreamCounts;
    Slot(StreamCounts& counts, std::string host) : counts_(counts), host_(std::move(host)) {}
    StreamCounts& counts_;
    std::string host_;
  };

  // RESOURCE_EXHAUSTED when the client or the server holds the most streams.
  absl::StatusOr<std::unique_ptr<Slot>> open(const std::string& peer);

 private:
  const int per_client_;
  const int total_;
  std::mutex mutex_;
  std::map<std::string, int> by_host_;
  int open_ = 0;
};

// Cancels streams that stall longer than their idle timeout or run past
// their deadline. One thread checks every registered stream a few times a
// second.
class StreamWatchdog {
 public:
  StreamWatchdog();
  ~StreamWatchdog();

  // One stream's registration; `touch()` after each step that progressed.
  class Ticket {
   public:
    ~Ticket();
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;
    void touch();
    // Why the watchdog cancelled the stream; empty if it did not.
    std::string cancelled_because() const;

   private:
    friend class StreamWatchdog;
    Ticket(StreamWatchdog& watchdog, uint64_t id) : watchdog_(watchdog), id_(id) {}
    StreamWatchdog& watchdog_;
    uint64_t id_;
  };

  // `idle`: longest time between touches; `total`: longest the stream may
  // live (absl::InfiniteDuration() for none). `what` names it in the reason.
  std::unique_ptr<Ticket> watch(grpc::ServerContextBase* context, absl::Duration idle,
                                absl::Duration total, std::string what);
  // For a stream that is idle by design between its messages (a callback
  // watch): stalled when `write_started()` is set (a write is outstanding,
  // nanoseconds since the epoch) and older than `idle`. Called with the
  // watchdog's lock held: it may only read atomics.
  std::unique_ptr<Ticket> watch_writes(grpc::ServerContextBase* context, absl::Duration idle,
                                       std::function<int64_t()> write_started, std::string what);

 private:
  struct Entry {
    grpc::ServerContextBase* context;
    absl::Duration idle;
    absl::Duration total;
    absl::Time deadline;
    absl::Time last_touch;
    std::string what;
    std::string cancelled_because;
    std::function<int64_t()> write_started;
    // The watchdog is cancelling this stream with its lock released.
    bool cancelling = false;
  };
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable cancelled_;
  std::map<uint64_t, Entry> entries_;
  uint64_t next_id_ = 1;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace labelmesh::server
