// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/text_header.h"

#include "core/header/header_checks.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {

std::optional<std::string_view> TextHeader::find(std::string_view key) const {
  auto it = fields.find(key);
  if (it == fields.end()) return std::nullopt;
  return std::string_view(it->second);
}

absl::StatusOr<TextHeader> parse_text_header(std::string_view path, std::string_view bytes,
                                             const TextHeaderSyntax& syntax, uint64_t max_bytes) {
  TextHeader header;
  size_t position = 0;
  int line_number = 0;
  while (true) {
    const size_t end = bytes.find('\n', position);
    if (end == std::string_view::npos) {
      if (bytes.size() >= max_bytes) {
        return field_error(path, "header", cat("does not end within ", max_bytes, " bytes"));
      }
      if (syntax.last_key.empty() && position == bytes.size()) {
        header.size = bytes.size();  // Detached header with no trailing blank line.
        return header;
      }
      return field_error(path, "header", "ends before its last field");
    }
    ++line_number;
    std::string_view line = bytes.substr(position, end - position);
    position = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) {
      if (syntax.last_key.empty()) {
        header.size = position;
        return header;
      }
      continue;
    }
    if (!syntax.comment.empty() && line.substr(0, syntax.comment.size()) == syntax.comment) {
      continue;
    }
    const size_t split = line.find(syntax.separator);
    if (!syntax.key_value_marker.empty()) {
      const size_t pair = line.find(syntax.key_value_marker);
      if (pair != std::string_view::npos && pair < split) {
        header.key_values.insert_or_assign(
            std::string(trim(line.substr(0, pair))),
            std::string(trim(line.substr(pair + syntax.key_value_marker.size()))));
        continue;
      }
    }
    if (split == std::string_view::npos) {
      if (line_number == 1) continue;  // Magic line (NRRD000X).
      return field_error(path, cat("header line ", line_number),
                         cat("has no \"", trim(syntax.separator), "\" between a key and a value"));
    }
    const std::string key(trim(line.substr(0, split)));
    const std::string value(trim(line.substr(split + syntax.separator.size())));
    header.fields.insert_or_assign(key, value);
    if (!syntax.last_key.empty() && key == syntax.last_key) {
      header.size = position;
      return header;
    }
  }
}

}  // namespace labelmesh::volume::internal
