// SPDX-License-Identifier: AGPL-3.0-or-later
// Line-oriented "key = value" / "key: value" headers (MetaImage, NRRD, INR).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace labelmesh::volume::internal {

struct TextHeader {
  // Keys as written (case kept), values trimmed.
  std::map<std::string, std::string, std::less<>> fields;
  // NRRD "key:=value" pairs, kept apart from the fields: keys as written,
  // values trimmed. 3D Slicer stores its segments' names and colours here.
  std::map<std::string, std::string, std::less<>> key_values;
  // Bytes from the start of the file to the first voxel byte.
  uint64_t size = 0;

  std::optional<std::string_view> find(std::string_view key) const;
};

struct TextHeaderSyntax {
  // Separator between key and value: "=" for MetaImage and INR, ": " for NRRD.
  std::string_view separator;
  // Lines starting with this are comments; empty for none.
  std::string_view comment;
  // The header ends after the line whose key is this (MetaImage's
  // ElementDataFile); empty when a blank line ends it (NRRD).
  std::string_view last_key;
  // Lines where this comes before any separator are key/value pairs, kept in
  // TextHeader::key_values (NRRD's ":="); empty for none.
  std::string_view key_value_marker;
};

// Splits the header at the start of `bytes` (at most max_bytes of it). Errors
// name the file; values are never echoed.
absl::StatusOr<TextHeader> parse_text_header(std::string_view path, std::string_view bytes,
                                             const TextHeaderSyntax& syntax, uint64_t max_bytes);

}  // namespace labelmesh::volume::internal
