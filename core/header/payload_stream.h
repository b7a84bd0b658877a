// SPDX-License-Identifier: AGPL-3.0-or-later
// Sequential, bounded reading of voxel bytes stored raw, gzip or zlib
// compressed, from some offset of a file. Used both to check that a payload
// is long enough and to read it; it never decodes more than it is asked for,
// whatever sizes the file claims.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/header/volume_header.h"

struct z_stream_s;

namespace labelmesh::volume::internal {

class PayloadStream {
 public:
  // `compressed_bytes` bounds the encoded bytes read after `file_offset`; 0
  // means to the end of the file.
  static absl::StatusOr<std::unique_ptr<PayloadStream>> open(const std::string& path,
                                                             uint64_t file_offset,
                                                             DataEncoding encoding,
                                                             uint64_t compressed_bytes = 0);
  ~PayloadStream();
  PayloadStream(const PayloadStream&) = delete;
  PayloadStream& operator=(const PayloadStream&) = delete;

  // Reads up to n decoded bytes into `out`; fewer only at the end of the data.
  absl::StatusOr<uint64_t> read(char* out, uint64_t n);
  // Like read() but discards the bytes.
  absl::StatusOr<uint64_t> skip(uint64_t n);
  // True once a compressed stream has reached its end with its checksum and
  // length verified by zlib and no bytes after it; always true for raw data.
  bool ended_cleanly() const { return encoding_ == DataEncoding::kRaw || finished_; }

 private:
  PayloadStream() = default;
  // Refills the input buffer; false at the end of the encoded bytes.
  bool refill();

  std::string path_;
  std::ifstream file_;
  DataEncoding encoding_ = DataEncoding::kRaw;
  uint64_t encoded_left_ = 0;
  std::unique_ptr<z_stream_s> zstream_;
  std::vector<unsigned char> input_;
  bool finished_ = false;
};

}  // namespace labelmesh::volume::internal
