// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_queue.h"

namespace labelmesh {

LabelQueue::LabelQueue(const std::vector<bool>& large) : large_(large) {
  for (size_t i = 0; i < large.size(); ++i) (large[i] ? large_order_ : small_order_).push_back(i);
}

std::optional<size_t> LabelQueue::take() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (ended_) return std::nullopt;
    if (!large_running_ && next_large_ < large_order_.size()) {
      large_running_ = true;
      return large_order_[next_large_++];
    }
    if (next_small_ < small_order_.size()) return small_order_[next_small_++];
    if (next_large_ == large_order_.size()) return std::nullopt;
    changed_.wait(lock);
  }
}

void LabelQueue::done(size_t index) {
  if (!large_[index]) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    large_running_ = false;
  }
  changed_.notify_all();
}

void LabelQueue::end() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
  }
  changed_.notify_all();
}

}  // namespace labelmesh
