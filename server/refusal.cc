// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/refusal.h"

#include <array>
#include <string>

namespace labelmesh::server {
namespace {

constexpr char kPayloadUrl[] = "type.labelmesh/refusal";

// In the enum's order.
constexpr std::array<std::string_view, 18> kCodes{
    "refused",           "shutting_down", "store_unavailable", "too_many_streams",
    "too_many_uploads",  "bad_request",   "too_large",         "request_in_progress",
    "request_id_reused", "queue_full",    "disk_full",         "spool_error",
    "bad_digest",        "bad_volume",    "stalled",           "too_slow",
    "unauthenticated",   "auth_backoff"};
static_assert(kCodes.size() == size_t(Refusal::kAuthBackoff) + 1, "one code per refusal");

}  // namespace

std::string_view refusal_code(Refusal why) { return kCodes[static_cast<size_t>(why)]; }

absl::Status refused(Refusal why, absl::Status status) {
  status.SetPayload(kPayloadUrl, absl::Cord(std::string(refusal_code(why))));
  return status;
}

Refusal refusal_of(const absl::Status& status, Refusal otherwise) {
  const auto payload = status.GetPayload(kPayloadUrl);
  if (!payload) return otherwise;
  const std::string code(*payload);
  for (size_t i = 0; i < kCodes.size(); ++i)
    if (kCodes[i] == code) return static_cast<Refusal>(i);
  return otherwise;
}

}  // namespace labelmesh::server
