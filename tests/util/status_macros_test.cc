// SPDX-License-Identifier: AGPL-3.0-or-later
// The early-return macros: a failed step's status is what the caller
// returns, and a successful one's value is what the caller gets. The IsOk
// matcher: what it says when a result is not ok.
#include "core/util/status_macros.h"
#include "support/status_matchers.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace labelmesh {
namespace {

absl::StatusOr<std::unique_ptr<int>> boxed(int value) {
  if (value < 0) return absl::OutOfRangeError("negative");
  return std::make_unique<int>(value);
}

// Moves the value out (a unique_ptr cannot be copied) or returns the error.
absl::StatusOr<int> unboxed_twice(int value) {
  LABELMESH_ASSIGN_OR_RETURN(std::unique_ptr<int> first, boxed(value));
  // A second one in the same scope, into a name declared before.
  std::unique_ptr<int> second;
  LABELMESH_ASSIGN_OR_RETURN(second, boxed(*first + 1));
  return *first + *second;
}

absl::Status checked(int value) {
  LABELMESH_RETURN_IF_ERROR(boxed(value));
  LABELMESH_RETURN_IF_ERROR(value == 7 ? absl::InternalError("seven") : absl::OkStatus());
  return absl::OkStatus();
}

TEST(StatusMacros, AssignOrReturnGivesTheValueOrTheError) {
  const auto sum = unboxed_twice(20);
  ASSERT_THAT(sum, testing::IsOk());
  EXPECT_EQ(*sum, 41);
  const auto failed = unboxed_twice(-1);
  EXPECT_EQ(failed.status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_EQ(failed.status().message(), "negative");
}

TEST(StatusMacros, ReturnIfErrorTakesStatusesAndStatusOrs) {
  EXPECT_THAT(checked(3), testing::IsOk());
  EXPECT_EQ(checked(-3).code(), absl::StatusCode::kOutOfRange);
  EXPECT_EQ(checked(7).code(), absl::StatusCode::kInternal);
}

// A result shaped like grpc::Status: ok() and a message apart.
struct RpcResult {
  bool ok() const { return message.empty(); }
  std::string error_message() const { return message; }
  std::string message;
};

// What IsOk says about `value` when it fails.
template <typename T>
std::string explained(const T& value) {
  ::testing::StringMatchResultListener listener;
  EXPECT_FALSE(::testing::ExplainMatchResult(testing::IsOk(), value, &listener));
  return listener.str();
}

TEST(StatusMatchers, IsOkSaysWhatAFailedResultSays) {
  EXPECT_EQ(explained(absl::NotFoundError("no liver")), "whose status is NOT_FOUND: no liver");
  EXPECT_EQ(explained(boxed(-1)), "whose status is OUT_OF_RANGE: negative");
  EXPECT_EQ(explained(RpcResult{"queue full"}), "whose status is queue full");
  EXPECT_THAT(RpcResult{}, testing::IsOk());
}

}  // namespace
}  // namespace labelmesh
