// SPDX-License-Identifier: AGPL-3.0-or-later
// Two pieces of work at once: both run, and an exception from either one
// reaches the caller after both are done.
#include "core/util/side_by_side.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

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

}  // namespace
}  // namespace labelmesh
