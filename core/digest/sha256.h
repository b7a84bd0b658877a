// SPDX-License-Identifier: AGPL-3.0-or-later
// SHA-256 of byte streams and files, as lowercase hex: how uploads and
// fetched artifacts are checked end to end.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace labelmesh::digest {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void update(std::string_view bytes);
  // 64 lowercase hex digits. Ends the computation.
  std::string hex_digest();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

std::string sha256_hex(std::string_view bytes);

// Errors: NOT_FOUND / INTERNAL naming the file.
absl::StatusOr<std::string> sha256_file(const std::string& path);

// True for exactly `digits` lowercase hex digits.
bool is_lower_hex(std::string_view text, size_t digits);

// True for 64 lowercase hex digits.
inline bool is_sha256_hex(std::string_view text) { return is_lower_hex(text, 64); }

// Equal contents, compared in time that does not depend on where they differ
// or on their lengths (both are hashed first): for secrets such as tokens.
bool constant_time_equal(std::string_view a, std::string_view b);

}  // namespace labelmesh::digest
