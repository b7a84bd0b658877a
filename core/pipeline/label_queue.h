// SPDX-License-Identifier: AGPL-3.0-or-later
// The order in which threads take labels to mesh: large labels one at a
// time, small labels beside them. A large label's Poisson solve uses every
// core and two large labels at once would double the peak memory, but a
// large label meshed from its voxel mask uses one core, and small labels keep
// the others busy meanwhile.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace labelmesh {

class LabelQueue {
 public:
  // `large[i]` says whether label i must not run beside another large one.
  // Large labels are taken first, in index order; small ones in index order.
  explicit LabelQueue(const std::vector<bool>& large);

  // The next label index for a thread, waiting while only large labels are
  // left and one of them is running; nullopt when none is left or after
  // end(). Each taken label must be given back with done().
  std::optional<size_t> take();
  void done(size_t index);
  // No label is taken after this (a stop or a fatal error).
  void end();

 private:
  // take() has an answer: a label a thread may run, or none left to wait for.
  bool answer_ready() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);

  const std::vector<bool> large_;
  std::vector<size_t> large_order_, small_order_;
  mutable absl::Mutex mutex_;
  size_t next_large_ ABSL_GUARDED_BY(mutex_) = 0;
  size_t next_small_ ABSL_GUARDED_BY(mutex_) = 0;
  bool large_running_ ABSL_GUARDED_BY(mutex_) = false;
  bool ended_ ABSL_GUARDED_BY(mutex_) = false;
};

}  // namespace labelmesh
