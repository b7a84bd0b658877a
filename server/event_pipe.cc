// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/event_pipe.h"

#include <unistd.h>

#include <cerrno>

#include "google/protobuf/io/coded_stream.h"

namespace labelmesh::server {

bool write_event(int fd, const v1::JobEvent& event) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.WriteVarint32(static_cast<uint32_t>(event.ByteSizeLong()));
    if (!event.SerializeToCodedStream(&coded)) return false;
  }
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

absl::StatusOr<std::optional<v1::JobEvent>> EventPipeReader::next() {
  google::protobuf::io::CodedInputStream coded(reinterpret_cast<const uint8_t*>(buffer_.data()),
                                               static_cast<int>(buffer_.size()));
  uint32_t size = 0;
  if (!coded.ReadVarint32(&size)) {
    // A varint is at most 5 bytes: more than that and still unreadable is garbage.
    if (buffer_.size() >= 5) return absl::InternalError("worker sent a malformed event");
    return std::nullopt;
  }
  if (size > kMaxMessageBytes) return absl::InternalError("worker sent an oversized event");
  const size_t header = static_cast<size_t>(coded.CurrentPosition());
  if (buffer_.size() - header < size) return std::nullopt;
  v1::JobEvent event;
  if (!event.ParseFromArray(buffer_.data() + header, static_cast<int>(size))) {
    return absl::InternalError("worker sent an event that does not parse");
  }
  buffer_.erase(0, header + size);
  return event;
}

}  // namespace labelmesh::server
