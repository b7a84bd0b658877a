// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/json_text.h"

#include "absl/strings/str_format.h"

namespace labelmesh::server {

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7f) {
      out += absl::StrFormat("\\u%04x", c);
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

}  // namespace labelmesh::server
