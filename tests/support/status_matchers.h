// SPDX-License-Identifier: AGPL-3.0-or-later
// gMock matchers for absl::Status and absl::StatusOr, which print the status
// when they fail:
//   EXPECT_THAT(read(path), testing::IsOk());
//   EXPECT_THAT(read(path), testing::StatusIs(absl::StatusCode::kInvalidArgument));
//   EXPECT_THAT(read(path), testing::StatusIs(absl::StatusCode::kInvalidArgument,
//                                             ::testing::HasSubstr("dims")));
#pragma once

#include <gmock/gmock.h>

#include <ostream>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/util/status_macros.h"

namespace labelmesh::testing {

MATCHER(IsOk, negation ? "is not ok" : "is ok") {
  const absl::Status& status = status_internal::status_of(arg);
  if (!status.ok()) *result_listener << "whose status is " << status;
  return status.ok();
}

MATCHER_P(StatusIs, code, "has status code " + absl::StatusCodeToString(code)) {
  const absl::Status& status = status_internal::status_of(arg);
  *result_listener << "whose status is " << status;
  return status.code() == code;
}

MATCHER_P2(StatusIs, code, message,
           "has status code " + absl::StatusCodeToString(code) + " and a message that " +
               ::testing::DescribeMatcher<std::string>(message)) {
  const absl::Status& status = status_internal::status_of(arg);
  *result_listener << "whose status is " << status;
  return status.code() == code && ::testing::Matches(message)(std::string(status.message()));
}

}  // namespace labelmesh::testing
