// SPDX-License-Identifier: AGPL-3.0-or-later
// Fuzzes the voxel payload stream (raw, gzip, zlib) and the checks built on
// it: check_raw_payload, check_encoded_payload, read_prefix and
// check_whole_payload. The first 8 bytes are the call's parameters, the rest
// the file:
//   byte 0     encoding (raw, gzip, zlib; modulo 3)
//   byte 1     offset of the payload in the file
//   bytes 2-3  compressed bytes (little-endian; 0 = to the end of the file)
//   bytes 4-5  size of each read() (little-endian, plus 1)
//   bytes 6-7  decoded bytes the header needs (little-endian, times 16)
// Raw reads must return exactly the file's bytes; no read may return more
// than asked for.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/header/header_checks.h"
#include "core/header/payload_stream.h"
#include "core/header/volume_header.h"
#include "fuzz/fuzz_support.h"

namespace {

using labelmesh::fuzzing::contract_broken;
namespace volume = labelmesh::volume;

constexpr size_t kParameterBytes = 8;
// The read() loop stops after this many calls or decoded bytes, whatever
// the stream still holds: a long stream in one-byte reads would take most of
// a second.
constexpr int kMaxReads = 4096;
constexpr uint64_t kMaxDecodedBytes = uint64_t{1} << 20;

uint64_t little_endian_16(const uint8_t* bytes) {
  return uint64_t{bytes[0]} | uint64_t{bytes[1]} << 8;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < kParameterBytes || size > labelmesh::fuzzing::kMaxInputBytes) return 0;
  const auto encoding = static_cast<volume::DataEncoding>(data[0] % 3);
  const uint64_t offset = data[1];
  const uint64_t compressed_bytes = little_endian_16(data + 2);
  const uint64_t chunk = little_endian_16(data + 4) + 1;
  const uint64_t needed = little_endian_16(data + 6) * 16;
  const uint8_t* file_bytes = data + kParameterBytes;
  const size_t file_size = size - kParameterBytes;
  const labelmesh::fuzzing::ScratchFile file(".bin", file_bytes, file_size);
  const std::string& path = file.path();

  auto stream = volume::internal::PayloadStream::open(path, offset, encoding, compressed_bytes);
  if (stream.ok()) {
    const bool raw = encoding == volume::DataEncoding::kRaw;
    const uint64_t left = file_size - offset;
    const uint64_t expected = compressed_bytes == 0 ? left : std::min(compressed_bytes, left);
    std::vector<char> buffer(chunk);
    uint64_t total = 0;
    bool at_end = false;
    for (int reads = 0; reads < kMaxReads && total < kMaxDecodedBytes && !at_end; ++reads) {
      auto got = (*stream)->read(buffer.data(), chunk);
      if (!got.ok()) break;
      if (*got > chunk) contract_broken("read() returned more than asked for");
      if (raw && (total + *got > expected ||
                  std::memcmp(buffer.data(), file_bytes + offset + total, *got) != 0))
        contract_broken("raw read() differs from the file");
      total += *got;
      at_end = *got == 0;
    }
    if (raw) {
      if (at_end && total != expected) contract_broken("raw read() ends before the file");
      if (!(*stream)->ended_cleanly()) contract_broken("a raw stream that did not end cleanly");
    }
  } else if (offset <= file_size) {
    contract_broken("open() refused an offset within the file");
  }

  if (encoding == volume::DataEncoding::kRaw) {
    const bool fits = offset <= file_size && file_size - offset >= needed;
    if (volume::internal::check_raw_payload(path, offset, needed).ok() != fits)
      contract_broken("check_raw_payload disagrees with the file's size");
  } else {
    (void)volume::internal::check_encoded_payload(path, offset, encoding, compressed_bytes, needed);
  }
  auto prefix = volume::internal::read_prefix(path, chunk, encoding == volume::DataEncoding::kGzip);
  if (prefix.ok() && prefix->size() > chunk) contract_broken("read_prefix returned too much");

  volume::VolumeHeader header;
  header.data_path = path;
  header.encoding = encoding;
  header.file_offset = offset;
  header.compressed_bytes = compressed_bytes;
  header.scalar_type = volume::ScalarType::kUInt8;
  header.geometry.dims = {static_cast<int64_t>(std::max<uint64_t>(needed, 1)), 1, 1};
  (void)volume::check_whole_payload(header);
  return 0;
}
