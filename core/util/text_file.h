// SPDX-License-Identifier: AGPL-3.0-or-later
// Buffered text output for the mesh writers: numbers in their shortest exact
// form, and one error naming the file at the end instead of a check per line.
#pragma once

#include <charconv>
#include <fstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "absl/status/status.h"
#include "core/util/text.h"

namespace labelmesh {

class TextFile {
 public:
  // `what` names the content in the error ("the volume mesh").
  TextFile(std::string path, std::string what)
      : path_(std::move(path)),
        what_(std::move(what)),
        out_(path_, std::ios::binary | std::ios::trunc) {}

  TextFile& operator<<(std::string_view text) {
    buffer_.append(text);
    if (buffer_.size() > (1u << 20)) flush();
    return *this;
  }
  TextFile& operator<<(char c) {
    buffer_.push_back(c);
    return *this;
  }
  // Integers in decimal; reals in the shortest form that reads back to the same double.
  template <typename T>
  requires std::is_arithmetic_v<T> TextFile& operator<<(T value) {
    char digits[32];
    const auto result = std::to_chars(digits, digits + sizeof digits, value);
    return *this << std::string_view(digits, static_cast<size_t>(result.ptr - digits));
  }

  // INTERNAL naming the file when anything failed to be written.
  absl::Status finish() {
    flush();
    out_.close();
    if (!out_) return absl::InternalError(cat(path_, ": could not write ", what_));
    return absl::OkStatus();
  }

 private:
  void flush() {
    if (out_) out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

  std::string path_;
  std::string what_;
  std::ofstream out_;
  std::string buffer_;
};

}  // namespace labelmesh
