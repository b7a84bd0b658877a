// SPDX-License-Identifier: AGPL-3.0-or-later
// JobEvents between a worker process and the server over a pipe, each as a
// varint length and the serialized message (protobuf's delimited form).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "labelmesh/v1/service.pb.h"

namespace labelmesh::server {

// Writes whole messages to a blocking descriptor. False when the reader is gone.
bool write_event(int fd, const v1::JobEvent& event);

// Collects bytes read from the pipe and hands back whole messages.
class EventPipeReader {
 public:
  // A report of a large multi-label run stays far under this.
  static constexpr uint32_t kMaxMessageBytes = 64u << 20;

  void append(const char* bytes, size_t size) { buffer_.append(bytes, size); }
  // The next whole message, nullopt when more bytes are needed, INTERNAL for
  // bytes that are not a message (a worker gone wrong).
  absl::StatusOr<std::optional<v1::JobEvent>> next();
  bool empty() const { return buffer_.empty(); }

 private:
  std::string buffer_;
};

}  // namespace labelmesh::server
