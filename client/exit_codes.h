// SPDX-License-Identifier: AGPL-3.0-or-later
// Process exit codes of the labelmesh CLI, and the one mapping from errors.
#pragma once

#include "absl/status/status.h"

namespace labelmesh::client {

enum ExitCode : int {
  kExitSuccess = 0,
  kExitUsage = 2,     // bad command line
  kExitBadInput = 3,  // the input file or an option about it is wrong
  kExitFailure = 4,   // a pipeline stage failed or was cancelled
  kExitService = 5,   // the server could not be reached or refused the call
};

inline int exit_code_for(const absl::Status& status) {
  if (status.ok()) return kExitSuccess;
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kOutOfRange:
      return kExitBadInput;
    default:
      return kExitFailure;
  }
}

inline constexpr const char* kExitCodeHelp =
    "Exit codes: 0 success, 2 bad usage, 3 bad input (file or option), 4 pipeline failure or "
    "cancelled, 5 server unreachable or call refused.";

}  // namespace labelmesh::client
