// SPDX-License-Identifier: AGPL-3.0-or-later
// Writes gzip files for tests.
#pragma once

#include <zlib.h>

#include <filesystem>
#include <string_view>

namespace labelmesh::testing {

inline bool write_gzip(const std::filesystem::path& path, std::string_view bytes) {
  gzFile file = gzopen(path.string().c_str(), "wb");
  if (file == nullptr) return false;
  const int n = gzwrite(file, bytes.data(), static_cast<unsigned>(bytes.size()));
  return gzclose(file) == Z_OK && n == static_cast<int>(bytes.size());
}

}  // namespace labelmesh::testing
