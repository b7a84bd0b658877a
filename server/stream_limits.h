// SPDX-License-Identifier: AGPL-3.0-or-later
// What one client can hold of the server: streams and uploads at once, per
// client, per host and in all, how long a stream may stall and how slowly it
// may transfer. A stalled stream (an upload whose next chunk does not come,
// a fetch or watch whose reader stopped reading) or one too slow is
// cancelled, which frees its thread and its upload slot.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/refusal.h"

namespace labelmesh::server {

// The largest chunk of an upload, and the size of a fetch's chunks.
inline constexpr size_t kChunkBytes = 1 << 20;

// The client part of a gRPC peer ("ipv4:10.0.0.7:53211" -> "ipv4:10.0.0.7").
std::string peer_host(const std::string& peer);

// Counts what each client, each host and all clients hold at once: open
// streams, or uploads in progress. The caller names the client and the host
// it counts under (client_identity.h, share_keys).
class StreamCounts {
 public:
  struct Limits {
    int per_client;
    int per_host;
    int total;
  };
  // `what` names the resource in refusals ("streams", "uploads"), which are
  // marked `when_full`.
  StreamCounts(Limits limits, std::string what, Refusal when_full)
      : limits_(limits), what_(std::move(what)), when_full_(when_full) {}

  // Holds one place until destroyed.
  class Slot {
   public:
    ~Slot();
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;

   private:
    friend class StreamCounts;
    Slot(StreamCounts& counts, std::string client, std::string host)
        : counts_(counts), client_(std::move(client)), host_(std::move(host)) {}
    StreamCounts& counts_;
    std::string client_;
    std::string host_;
  };

  // RESOURCE_EXHAUSTED when the server, the client or its host holds the most.
  absl::StatusOr<std::unique_ptr<Slot>> open(const std::string& client, const std::string& host);

 private:
  const Limits limits_;
  const std::string what_;
  const Refusal when_full_;
  absl::Mutex mutex_;
  // Only keys with a place held: a key is erased when its count drops to 0.
  std::map<std::string, int> by_client_ ABSL_GUARDED_BY(mutex_);
  std::map<std::string, int> by_host_ ABSL_GUARDED_BY(mutex_);
  int open_ ABSL_GUARDED_BY(mutex_) = 0;
};

// The least a transfer must move, in every window of its own once its
// bytes have started: a client that trickles bytes keeps a stream from
// stalling, not from being too slow.
struct TransferRate {
  uint64_t bytes_per_second = 0;  // 0: no minimum
  absl::Duration window = absl::Seconds(30);
};

// Cancels streams that stall longer than their idle timeout, run past their
// deadline or transfer under their minimum rate. One thread checks every registered stream a few
// times a second.
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
    // Progress that moved bytes, `transferred` in all so far. The first one
    // starts the rate windows, from the touch before it (the request).
    void touch(uint64_t transferred);
    // The bytes are all in: no minimum rate from now on.
    void end_transfer();
    // DEADLINE_EXCEEDED saying why, marked stalled or too_slow, when the
    // watchdog cancelled the stream; OK otherwise.
    absl::Status cancellation() const;
    // The cancellation when there is one, else `otherwise`: how a stream
    // that stopped ends.
    absl::Status cancellation_or(absl::Status otherwise) const;

   private:
    friend class StreamWatchdog;
    Ticket(StreamWatchdog& watchdog, uint64_t id) : watchdog_(watchdog), id_(id) {}
    bool may_end() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(watchdog_.mutex_);
    StreamWatchdog& watchdog_;
    uint64_t id_;
  };

  // `idle`: longest time between touches; `total`: longest the stream may
  // live (absl::InfiniteDuration() for none); `rate`: the least it must
  // move. `what` names it in the reason.
  std::unique_ptr<Ticket> watch(grpc::ServerContextBase* context, absl::Duration idle,
                                absl::Duration total, std::string what, TransferRate rate = {});
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
    absl::Status cancellation;
    std::function<int64_t()> write_started;
    // The watchdog is cancelling this stream with its lock released.
    bool cancelling = false;
    struct Transfer {
      TransferRate rate;
      // Set by the first touch with bytes.
      bool started = false;
      // The current window, and the bytes moved before it and in all.
      absl::Time window_start;
      uint64_t window_bytes = 0;
      uint64_t bytes = 0;
    } transfer;
  };
  void loop();
  // A ticket's end may go on: its entry is gone, not being cancelled, or the
  // end runs on the watchdog's own thread.
  bool may_erase(uint64_t id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);

  // Waits are on conditions the mutex re-checks as it is released.
  mutable absl::Mutex mutex_;
  std::map<uint64_t, Entry> entries_ ABSL_GUARDED_BY(mutex_);
  uint64_t next_id_ ABSL_GUARDED_BY(mutex_) = 1;
  bool stopping_ ABSL_GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace labelmesh::server
