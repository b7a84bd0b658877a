// SPDX-License-Identifier: AGPL-3.0-or-later
// Small string helpers that take std::string_view. Debian's abseil is built
// with its own absl::string_view, so absl's string utilities do not accept
// std::string_view; these keep the rest of the code on the standard type.
#pragma once

#include <cctype>
#include <cstdio>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace labelmesh {

namespace text_internal {

inline void append(std::string& out, std::string_view piece) { out.append(piece); }
inline void append(std::string& out, const char* piece) { out.append(piece); }
inline void append(std::string& out, const std::string& piece) { out.append(piece); }
inline void append(std::string& out, char piece) { out.push_back(piece); }
template <typename T>
requires std::is_arithmetic_v<T>
void append(std::string& out, T value) {
  if constexpr (std::is_floating_point_v<T>) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", static_cast<double>(value));
    out.append(buffer);
  } else {
    out.append(std::to_string(value));
  }
}

}  // namespace text_internal

// Concatenates strings and numbers (reals with 9 significant digits).
template <typename... Pieces>
std::string cat(const Pieces&... pieces) {
  std::string out;
  (text_internal::append(out, pieces), ...);
  return out;
}

// `value` with `decimals` digits after the point ("-8.4").
inline std::string format_fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

inline bool contains(std::string_view text, std::string_view part) {
  return text.find(part) != std::string_view::npos;
}

inline std::string to_lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

inline bool equals_ignore_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && to_lower(a) == to_lower(b);
}

inline std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}

// Splits at any of `separators`, dropping empty pieces.
inline std::vector<std::string_view> split_any(std::string_view text, std::string_view separators) {
  std::vector<std::string_view> pieces;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = text.find_first_of(separators, start);
    const size_t stop = end == std::string_view::npos ? text.size() : end;
    if (stop > start) pieces.push_back(text.substr(start, stop - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return pieces;
}

}  // namespace labelmesh
