// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

namespace labelmesh {
namespace {

TEST(LabelQueue, LargeLabelsFirstThenSmallInIndexOrder) {
  LabelQueue queue({false, true, false, true});
  std::vector<size_t> taken;
  // One thread: a large label, then small ones beside it, then the next large.
  taken.push_back(*queue.take());
  taken.push_back(*queue.take());
  taken.push_back(*queue.take());
  EXPECT_EQ(taken, (std::vector<size_t>{1, 0, 2}));
  queue.done(0);
  queue.done(2);
  queue.done(1);
  EXPECT_EQ(queue.take(), 3u);
  queue.done(3);
  EXPECT_FALSE(queue.take().has_value());
}

TEST(LabelQueue, NeverTwoLargeAtOnceAndEveryLabelOnce) {
  std::vector<bool> large(40);
  for (size_t i = 0; i < large.size(); ++i) large[i] = i % 3 == 0;
  LabelQueue queue(large);
  std::atomic<int> large_running{0}, most_large{0}, small_beside_large{0};
  std::mutex mutex;
  std::vector<size_t> seen;
  auto work = [&] {
    while (const auto i = queue.take()) {
      if (large[*i]) {
        const int now = ++large_running;
        int most = most_large.load();
        while (now > most && !most_large.compare_exchange_weak(most, now)) {
        }
      } else if (large_running.load() > 0) {
        ++small_beside_large;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(large[*i] ? 5 : 1));
      {
        std::lock_guard<std::mutex> lock(mutex);
        seen.push_back(*i);
      }
      if (large[*i]) --large_running;
      queue.done(*i);
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back(work);
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(most_large.load(), 1);
  EXPECT_GT(small_beside_large.load(), 0);
  std::sort(seen.begin(), seen.end());
  ASSERT_EQ(seen.size(), large.size());
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i);
}

TEST(LabelQueue, EndStopsTakingAndWakesWaiters) {
  LabelQueue queue({true, true});
  ASSERT_EQ(queue.take(), 0u);
  std::thread waiter([&] { EXPECT_FALSE(queue.take().has_value()); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.end();
  waiter.join();
  queue.done(0);
  EXPECT_FALSE(queue.take().has_value());
}

}  // namespace
}  // namespace labelmesh
