// SPDX-License-Identifier: AGPL-3.0-or-later
// Why the server refused a call, as a code its metrics count and its audit
// log names (never text from an upload). The code travels on the
// absl::Status as a payload, so the layer that knows why (the spool, the job
// table, the watchdog) marks it and the service reads it back without
// parsing messages.
#pragma once

#include <cstdint>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh::server {

enum class Refusal : uint8_t {
  kRefused,  // no more precise reason
  kShuttingDown,
  kStoreUnavailable,
  kTooManyStreams,
  kTooManyUploads,
  kBadRequest,
  kTooLarge,
  kRequestInProgress,
  kRequestIdReused,
  kQueueFull,
  kDiskFull,
  kSpoolError,
  kBadDigest,
  kBadVolume,
  kStalled,
  kTooSlow,
  kUnauthenticated,
  kAuthBackoff,
};

// The code: "queue_full", "bad_volume", ...
std::string_view refusal_code(Refusal why);

// `status` (not OK) marked with why it refuses; an earlier mark is replaced.
absl::Status refused(Refusal why, absl::Status status);

// The mark on `status`, or `otherwise` when it has none.
Refusal refusal_of(const absl::Status& status, Refusal otherwise = Refusal::kRefused);

}  // namespace labelmesh::server
