// SPDX-License-Identifier: AGPL-3.0-or-later
// gMock matchers for absl::Status and absl::StatusOr, which print the status
// when they fail (IsOk also takes other results with ok(): grpc::Status,
// protobuf's util Status, the mesh checks):
//   EXPECT_THAT(read(path), testing::IsOk());
//   EXPECT_THAT(read(path), testing::StatusIs(absl::StatusCode::kInvalidArgument));
//   EXPECT_THAT(read(path), testing::StatusIs(absl::StatusCode::kInvalidArgument,
//                                             ::testing::HasSubstr("dims")));
#pragma once

#include <gmock/gmock.h>

#include <ostream>
#include <string>
#include <type_traits>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/util/status_macros.h"

namespace labelmesh::testing {

// What a failed status says: absl's and protobuf's as they print, gRPC's
// message; a result without one only says it is not ok.
template <typename S>
std::string status_text(const S& status) {
  if constexpr (std::is_convertible_v<const S&, const absl::Status&>) {
    return static_cast<const absl::Status&>(status).ToString();
  } else if constexpr (requires { status.error_message(); }) {
    return status.error_message();
  } else if constexpr (requires { status.ToString(); }) {
    return status.ToString();
  } else {
    return "not ok";
  }
}

MATCHER(IsOk, negation ? "is not ok" : "is ok") {
  const auto& status = status_internal::status_of(arg);
  if (!status.ok()) *result_listener << "whose status is " << status_text(status);
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
