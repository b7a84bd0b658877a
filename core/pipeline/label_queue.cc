// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_queue.h"

namespace labelmesh {

LabelQueue::LabelQueue(const std::vector<bool>& large) : large_(large) {
  for (size_t i = 0; i < large.size(); ++i) (large[i] ? large_order_ : small_order_).push_back(i);
}

bool LabelQueue::answer_ready() const {
  return ended_ || (!large_running_ && next_large_ < large_order_.size()) ||
         next_small_ < small_order_.size() || next_large_ == large_order_.size();
}

std::optional<size_t> LabelQueue::take() {
  absl::MutexLock lock(&mutex_);
  mutex_.Await(absl::Condition(this, &LabelQueue::answer_ready));
  if (ended_) return std::nullopt;
  if (!large_running_ && next_large_ < large_order_.size()) {
    large_running_ = true;
    return large_order_[next_large_++];
  }
  if (next_small_ < small_order_.size()) return small_order_[next_small_++];
  return std::nullopt;
}

void LabelQueue::done(size_t index) {
  if (!large_[index]) return;
  absl::MutexLock lock(&mutex_);
  large_running_ = false;
}

void LabelQueue::end() {
  absl::MutexLock lock(&mutex_);
  ended_ = true;
}

}  // namespace labelmesh
