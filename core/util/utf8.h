// SPDX-License-Identifier: AGPL-3.0-or-later
// Text from files (DICOM names in a file's own character set, label tables
// in any encoding) made valid UTF-8 before it reaches a protobuf string
// field, whose parser refuses anything else.
#pragma once

#include <string>
#include <string_view>

namespace labelmesh {

// `text` with every byte that does not start a well-formed UTF-8 sequence
// (and every control character) replaced by '?'.
inline std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  size_t i = 0;
  while (i < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    size_t length = byte < 0x80           ? 1
                    : (byte >> 5) == 0x6  ? 2
                    : (byte >> 4) == 0xE  ? 3
                    : (byte >> 3) == 0x1E ? 4
                                          : 0;
    bool well_formed = length > 0 && i + length <= text.size();
    for (size_t k = 1; well_formed && k < length; ++k)
      well_formed = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (well_formed && length > 1) {
      // No overlong forms, surrogates or code points past U+10FFFF.
      const auto second = static_cast<unsigned char>(text[i + 1]);
      well_formed = !(byte == 0xC0 || byte == 0xC1) && !(byte == 0xE0 && second < 0xA0) &&
                    !(byte == 0xED && second >= 0xA0) && !(byte == 0xF0 && second < 0x90) &&
                    !(byte == 0xF4 && second >= 0x90) && byte <= 0xF4;
    }
    if (!well_formed) {
      out.push_back('?');
      ++i;
      continue;
    }
    if (length == 1 && (byte < 0x20 || byte == 0x7F)) {
      out.push_back('?');
    } else {
      out.append(text.substr(i, length));
    }
    i += length;
  }
  return out;
}

// The longest prefix of valid UTF-8 `text` of at most `bytes` bytes that
// ends on a whole character.
inline std::string_view utf8_prefix(std::string_view text, size_t bytes) {
  if (text.size() <= bytes) return text;
  size_t end = bytes;
  // Back up over continuation bytes to the start of the cut character.
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return text.substr(0, end);
}

}  // namespace labelmesh
