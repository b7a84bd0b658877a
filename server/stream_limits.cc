// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/stream_limits.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

std::string peer_host(const std::string& peer) {
  const size_t colon = peer.rfind(':');
  const size_t scheme = peer.find(':');
  if (colon == std::string::npos || colon == scheme) return peer;
  return peer.substr(0, colon);
}

StreamCounts::Slot::~Slot() {
  absl::MutexLock lock(&counts_.mutex_);
  if (--counts_.by_client_[client_] == 0) counts_.by_client_.erase(client_);
  if (--counts_.by_host_[host_] == 0) counts_.by_host_.erase(host_);
  --counts_.open_;
}

absl::StatusOr<std::unique_ptr<StreamCounts::Slot>> StreamCounts::open(const std::string& client,
                                                                       const std::string& host) {
  auto held = [](const std::map<std::string, int>& counts, const std::string& key) {
    auto it = counts.find(key);
    return it == counts.end() ? 0 : it->second;
  };
  absl::MutexLock lock(&mutex_);
  const auto full = [&](const std::string& message) {
    return refused(when_full_, absl::ResourceExhaustedError(message));
  };
  if (open_ >= limits_.total) {
    return full(absl::StrCat("the server holds its most ", what_, " (", limits_.total,
                             "); try again later"));
  }
  if (held(by_client_, client) >= limits_.per_client) {
    return full(absl::StrCat("this client holds its most ", what_, " at once (", limits_.per_client,
                             "); close one first"));
  }
  if (held(by_host_, host) >= limits_.per_host) {
    return full(absl::StrCat("this client's host holds its most ", what_, " at once (",
                             limits_.per_host, "); try again later"));
  }
  ++by_client_[client];
  ++by_host_[host];
  ++open_;
  return std::unique_ptr<Slot>(new Slot(*this, client, host));
}

StreamWatchdog::StreamWatchdog() : thread_([this] { loop(); }) {}

StreamWatchdog::~StreamWatchdog() {
  {
    absl::MutexLock lock(&mutex_);
    stopping_ = true;
  }
  thread_.join();
}

bool StreamWatchdog::may_erase(uint64_t id) const {
  auto it = entries_.find(id);
  return it == entries_.end() || !it->second.cancelling ||
         std::this_thread::get_id() == thread_.get_id();
}

bool StreamWatchdog::Ticket::may_end() const { return watchdog_.may_erase(id_); }

StreamWatchdog::Ticket::~Ticket() {
  absl::MutexLock lock(&watchdog_.mutex_);
  // The stream's context must outlive a TryCancel in flight on it.
  watchdog_.mutex_.Await(absl::Condition(this, &Ticket::may_end));
  watchdog_.entries_.erase(id_);
}

void StreamWatchdog::Ticket::touch() {
  absl::MutexLock lock(&watchdog_.mutex_);
  auto it = watchdog_.entries_.find(id_);
  if (it != watchdog_.entries_.end()) it->second.last_touch = absl::Now();
}

void StreamWatchdog::Ticket::touch(uint64_t transferred) {
  absl::MutexLock lock(&watchdog_.mutex_);
  auto it = watchdog_.entries_.find(id_);
  if (it == watchdog_.entries_.end()) return;
  Entry& entry = it->second;
  if (!entry.transfer.started) {
    // The first bytes were on their way since the request came.
    entry.transfer.started = true;
    entry.transfer.window_start = entry.last_touch;
  }
  entry.transfer.bytes = transferred;
  entry.last_touch = absl::Now();
}

void StreamWatchdog::Ticket::end_transfer() {
  absl::MutexLock lock(&watchdog_.mutex_);
  auto it = watchdog_.entries_.find(id_);
  if (it != watchdog_.entries_.end()) it->second.transfer.rate.bytes_per_second = 0;
}

absl::Status StreamWatchdog::Ticket::cancellation() const {
  absl::MutexLock lock(&watchdog_.mutex_);
  auto it = watchdog_.entries_.find(id_);
  return it == watchdog_.entries_.end() ? absl::OkStatus() : it->second.cancellation;
}

absl::Status StreamWatchdog::Ticket::cancellation_or(absl::Status otherwise) const {
  absl::Status cancelled = cancellation();
  return cancelled.ok() ? otherwise : cancelled;
}

std::unique_ptr<StreamWatchdog::Ticket> StreamWatchdog::watch(grpc::ServerContextBase* context,
                                                              absl::Duration idle,
                                                              absl::Duration total,
                                                              std::string what, TransferRate rate) {
  const absl::Time now = absl::Now();
  absl::MutexLock lock(&mutex_);
  const uint64_t id = next_id_++;
  Entry entry{context, idle, total, now + total, now, std::move(what), {}, nullptr, false, {}};
  entry.transfer.rate = rate;
  entries_[id] = std::move(entry);
  return std::unique_ptr<Ticket>(new Ticket(*this, id));
}

std::unique_ptr<StreamWatchdog::Ticket> StreamWatchdog::watch_writes(
    grpc::ServerContextBase* context, absl::Duration idle, std::function<int64_t()> write_started,
    std::string what) {
  const absl::Time now = absl::Now();
  absl::MutexLock lock(&mutex_);
  const uint64_t id = next_id_++;
  entries_[id] = Entry{context,
                       idle,
                       absl::InfiniteDuration(),
                       absl::InfiniteFuture(),
                       now,
                       std::move(what),
                       {},
                       std::move(write_started),
                       false,
                       {}};
  return std::unique_ptr<Ticket>(new Ticket(*this, id));
}

void StreamWatchdog::loop() {
  // Locked and unlocked by hand: each cancel runs with the lock released.
  mutex_.Lock();
  while (!mutex_.AwaitWithTimeout(absl::Condition(&stopping_), absl::Milliseconds(100))) {
    const absl::Time now = absl::Now();
    std::vector<uint64_t> to_cancel;
    for (auto& [id, entry] : entries_) {
      if (!entry.cancellation.ok()) continue;
      absl::Time busy_since = entry.last_touch;
      if (entry.write_started) {
        const int64_t started = entry.write_started();
        busy_since = started == 0 ? now : absl::FromUnixNanos(started);
      }
      Entry::Transfer& transfer = entry.transfer;
      if (now - busy_since > entry.idle) {
        entry.cancellation =
            refused(Refusal::kStalled,
                    absl::DeadlineExceededError(absl::StrCat(entry.what, " stalled for more than ",
                                                             absl::FormatDuration(entry.idle))));
      } else if (now > entry.deadline) {
        entry.cancellation = refused(
            Refusal::kStalled,
            absl::DeadlineExceededError(absl::StrCat(entry.what, " ran past its deadline of ",
                                                     absl::FormatDuration(entry.total))));
      } else if (transfer.rate.bytes_per_second > 0 && transfer.started &&
                 now - transfer.window_start >= transfer.rate.window) {
        // Window by window, not on average since the start: a fast start
        // must not pay for a trickle after it.
        const double seconds = absl::ToDoubleSeconds(now - transfer.window_start);
        const uint64_t moved = transfer.bytes - transfer.window_bytes;
        if (moved >= transfer.rate.bytes_per_second * seconds) {
          transfer.window_start = now;
          transfer.window_bytes = transfer.bytes;
          continue;
        }
        entry.cancellation = refused(
            Refusal::kTooSlow,
            absl::DeadlineExceededError(absl::StrFormat(
                "%s too slow: %.1f KiB/s over the last %s, under the minimum of %.1f KiB/s",
                entry.what, moved / 1024.0 / seconds, absl::FormatDuration(transfer.rate.window),
                transfer.rate.bytes_per_second / 1024.0)));
      } else {
        continue;
      }
      spdlog::warn("{}: cancelled", std::string(entry.cancellation.message()));
      entry.cancelling = true;
      to_cancel.push_back(id);
    }
    // Cancelled with the lock released: gRPC may run the stream's reactions
    // on other threads meanwhile, and those may end the stream.
    for (uint64_t id : to_cancel) {
      grpc::ServerContextBase* context = entries_.at(id).context;
      mutex_.Unlock();
      context->TryCancel();
      mutex_.Lock();
      if (auto it = entries_.find(id); it != entries_.end()) it->second.cancelling = false;
    }
  }
  mutex_.Unlock();
}

}  // namespace labelmesh::server
