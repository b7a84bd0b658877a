// SPDX-License-Identifier: AGPL-3.0-or-later
// Two pieces of work at once: both run, and an exception from either one
// reaches the caller after both are done; a range split in two halves
// visits every index once.
#include "core/util/side_by_side.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace labelmesh {
namespace {

TEST(SideBySide, RunsBoth) {
  std::atomic<int> ran{0};
  side_by_side([&] { ++ran; }, [&] { ++ran; });
  EXPECT_EQ(ran, 2);
}

TEST(SideBySide, AnExceptionOnTheSecondThreadReachesTheCaller) {
  bool here_finished = false;
  EXPECT_THROW(
      side_by_side([] { throw std::runtime_error("there"); }, [&] { here_finished = true; }),
      std::runtime_error);
  EXPECT_TRUE(here_finished);
}

TEST(SideBySide, AnExceptionHereWaitsForTheOtherThread) {
  std::atomic<bool> there_finished{false};
  EXPECT_THROW(side_by_side([&] { there_finished = true; }, [] { throw std::logic_error("here"); }),
               std::logic_error);
  EXPECT_TRUE(there_finished);
}

TEST(InTwoHalves, EveryIndexOnceInTwoRanges) {
  for (const size_t count : {size_t{0}, size_t{1}, size_t{2}, size_t{7}, size_t{1000}}) {
    std::vector<int> visits(count, 0);
    std::atomic<int> ranges{0};
    in_two_halves(count, [&](size_t begin, size_t end) {
      ++ranges;
      for (size_t i = begin; i < end; ++i) ++visits[i];
    });
    EXPECT_EQ(ranges, 2);
    for (size_t i = 0; i < count; ++i) EXPECT_EQ(visits[i], 1) << "index " << i << " of " << count;
  }
}

}  // namespace
}  // namespace labelmesh
