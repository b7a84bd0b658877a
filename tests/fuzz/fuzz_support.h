// SPDX-License-Identifier: AGPL-3.0-or-later
// What the fuzz harnesses share: a scratch file for checks that read paths
// rather than memory, the input size bound, and a loud failure for a broken
// contract (libFuzzer and the replay test both report an abort).
#pragma once

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "core/header/image_geometry.h"

namespace labelmesh::fuzzing {

// Inputs larger than this are skipped: the checks' bounds are what is
// tested, not how fast zlib inflates a megabyte.
inline constexpr size_t kMaxInputBytes = size_t{1} << 20;

// The process's private directory under TMPDIR, made on first use and
// removed, with anything left in it, when the process exits normally or a
// contract is broken.
class ScratchDirectory {
 public:
  static const std::filesystem::path& get() {
    static const ScratchDirectory directory;
    return directory.path_;
  }
  // Removes the directory now, when one was made: before an abort, which
  // skips the destructor.
  static void remove_if_made() {
    std::error_code error;
    if (made_ != nullptr) std::filesystem::remove_all(made_->path_, error);
  }

 private:
  ScratchDirectory() {
    std::error_code error;
    std::filesystem::path base = std::filesystem::temp_directory_path(error);
    if (error) base = "/tmp";
    std::string pattern = (base / "labelmesh-fuzz-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("fuzz: mkdtemp");
      std::abort();
    }
    path_ = pattern;
    made_ = this;
  }
  ~ScratchDirectory() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
    made_ = nullptr;
  }

  std::filesystem::path path_;
  static inline const ScratchDirectory* made_ = nullptr;
};

// Stops the run with a message: a check returned something its contract
// rules out.
[[noreturn]] inline void contract_broken(std::string_view what) {
  std::fprintf(stderr, "fuzz: contract broken: %.*s\n", static_cast<int>(what.size()), what.data());
  ScratchDirectory::remove_if_made();
  std::abort();
}

// What every accepted header promises about its grid: sizes of at least 1
// within the voxel limit, finite positive spacing, a finite origin and unit,
// non-coplanar axis directions.
inline void check_geometry_contract(const volume::ImageGeometry& g, uint64_t max_voxels) {
  uint64_t voxels = 1;
  for (int axis = 0; axis < 3; ++axis) {
    if (g.dims[axis] < 1) contract_broken("a size below 1");
    voxels *= static_cast<uint64_t>(g.dims[axis]);
    if (voxels > max_voxels) contract_broken("more voxels than the limit");
    if (!std::isfinite(g.spacing[axis]) || !(g.spacing[axis] > 0))
      contract_broken("spacing not finite and positive");
    if (!std::isfinite(g.origin[axis])) contract_broken("origin not finite");
    double norm2 = 0;
    for (int row = 0; row < 3; ++row) {
      const double d = g.direction[3 * row + axis];
      if (!std::isfinite(d)) contract_broken("direction not finite");
      norm2 += d * d;
    }
    if (std::abs(norm2 - 1) > 1e-9) contract_broken("direction column not of unit length");
  }
  const auto& d = g.direction;
  const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                     d[2] * (d[3] * d[7] - d[4] * d[6]);
  // header_checks.cc refuses |det| < 1e-6; a hair of slack for rounding.
  if (!(std::abs(det) >= 0.999e-6)) contract_broken("coplanar axis directions");
}

// One input as a file, "volume<extension>" in the scratch directory (always
// the same name, so runs are repeatable), removed when this goes out of scope.
class ScratchFile {
 public:
  ScratchFile(std::string_view extension, const uint8_t* data, size_t size)
      : path_((ScratchDirectory::get() / ("volume" + std::string(extension))).string()) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) contract_broken("cannot write the scratch file");
  }
  ~ScratchFile() {
    std::error_code error;
    std::filesystem::remove(path_, error);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace labelmesh::fuzzing
