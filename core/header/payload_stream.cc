// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/payload_stream.h"

#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

constexpr size_t kChunk = size_t{1} << 20;
// zlib windowBits: 15-bit window, +32 to accept either a zlib or a gzip header.
constexpr int kAutoDetectWindowBits = 15 + 32;

}  // namespace

absl::StatusOr<std::unique_ptr<PayloadStream>> PayloadStream::open(const std::string& path,
                                                                   uint64_t file_offset,
                                                                   DataEncoding encoding,
                                                                   uint64_t compressed_bytes) {
  LABELMESH_ASSIGN_OR_RETURN(auto size, file_size(path));
  if (file_offset > size) {
    return field_error(path, "voxel data",
                       cat("offset ", file_offset, " is past the end of the file"));
  }
  std::unique_ptr<PayloadStream> stream(new PayloadStream());
  stream->path_ = path;
  stream->encoding_ = encoding;
  stream->encoded_left_ =
      compressed_bytes == 0 ? size - file_offset : std::min(compressed_bytes, size - file_offset);
  stream->file_.open(path, std::ios::binary);
  if (!stream->file_) return absl::NotFoundError(cat(path, ": cannot open the file"));
  stream->file_.seekg(static_cast<std::streamoff>(file_offset));
  if (encoding != DataEncoding::kRaw) {
    stream->zstream_ = std::make_unique<z_stream_s>();
    *stream->zstream_ = z_stream_s{};
    if (inflateInit2(stream->zstream_.get(), kAutoDetectWindowBits) != Z_OK) {
      stream->zstream_.reset();
      return absl::InternalError("zlib could not start a decoder");
    }
    // No larger than the encoded bytes: a small file needs no megabyte.
    stream->input_.resize(std::clamp<uint64_t>(stream->encoded_left_, 1, kChunk));
  }
  return stream;
}

PayloadStream::~PayloadStream() {
  if (zstream_) inflateEnd(zstream_.get());
}

bool PayloadStream::refill() {
  if (encoded_left_ == 0) return false;
  file_.read(reinterpret_cast<char*>(input_.data()),
             static_cast<std::streamsize>(std::min<uint64_t>(encoded_left_, input_.size())));
  const auto n = static_cast<uint64_t>(file_.gcount());
  if (n == 0) return false;
  encoded_left_ -= n;
  zstream_->next_in = input_.data();
  zstream_->avail_in = static_cast<uInt>(n);
  return true;
}

absl::StatusOr<uint64_t> PayloadStream::read(char* out, uint64_t n) {
  if (encoding_ == DataEncoding::kRaw) {
    const uint64_t want = std::min(n, encoded_left_);
    file_.read(out, static_cast<std::streamsize>(want));
    const auto got = static_cast<uint64_t>(file_.gcount());
    encoded_left_ -= got;
    return got;
  }
  uint64_t produced = 0;
  while (produced < n && !finished_) {
    if (zstream_->avail_in == 0 && !refill()) break;
    zstream_->next_out = reinterpret_cast<unsigned char*>(out + produced);
    zstream_->avail_out = static_cast<uInt>(std::min<uint64_t>(n - produced, kChunk));
    const uInt before = zstream_->avail_out;
    const int result = inflate(zstream_.get(), Z_NO_FLUSH);
    produced += before - zstream_->avail_out;
    if (result == Z_STREAM_END) {
      // gzip files may hold several members back to back: go on if bytes remain.
      if (zstream_->avail_in == 0 && !refill()) {
        finished_ = true;
        break;
      }
      inflateReset(zstream_.get());
      continue;
    }
    if (result == Z_DATA_ERROR || result == Z_NEED_DICT || result == Z_MEM_ERROR ||
        result == Z_STREAM_ERROR) {
      return field_error(path_, "compressed voxel data", "is corrupt");
    }
  }
  return produced;
}

absl::StatusOr<uint64_t> PayloadStream::skip(uint64_t n) {
  // Left uninitialised: only the pages the decoder writes are touched.
  const auto sink_size = static_cast<size_t>(std::min<uint64_t>(n, kChunk));
  const auto sink = std::make_unique_for_overwrite<char[]>(sink_size);
  uint64_t skipped = 0;
  while (skipped < n) {
    LABELMESH_ASSIGN_OR_RETURN(auto got,
                               read(sink.get(), std::min<uint64_t>(n - skipped, sink_size)));
    if (got == 0) break;
    skipped += got;
  }
  return skipped;
}

}  // namespace labelmesh::volume::internal
