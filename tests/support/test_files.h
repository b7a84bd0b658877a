// SPDX-License-Identifier: AGPL-3.0-or-later
// Paths and scratch files for tests.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

namespace labelmesh::testing {

// ../shared/data beside the checkout: the real segmentations; the
// environment's LABELMESH_SHARED_DATA, when set, names another copy.
inline std::string shared_data(std::string_view name) {
  const char* elsewhere = std::getenv("LABELMESH_SHARED_DATA");
  const std::filesystem::path dir =
      elsewhere != nullptr && *elsewhere != '\0' ? elsewhere : LABELMESH_SHARED_DATA;
  return (dir / std::string(name)).string();
}

// Skips the running test, naming the folder, when the real segmentations
// are missing (a clone without ../shared/data): never a crash or a failure.
#define LABELMESH_SKIP_WITHOUT_SHARED_DATA()                                \
  if (const auto sources = ::labelmesh::testing::shared_data("SOURCES.md"); \
      !std::filesystem::exists(sources))                                    \
  GTEST_SKIP() << "missing the real segmentations (" << sources             \
               << "): ../shared/data beside the checkout"

// A fresh directory for one test, removed by the next run of the same test.
// It sits under the running test's own name, so tests that ctest runs side by
// side never share one, whatever name they pass.
inline std::filesystem::path scratch_dir(std::string_view name) {
  auto dir = std::filesystem::temp_directory_path() / "labelmesh-tests";
  if (const auto* test = ::testing::UnitTest::GetInstance()->current_test_info())
    dir /= std::string(test->test_suite_name()) + "." + test->name();
  dir /= std::string(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// How many entries `dir` holds (0 when it cannot be read).
inline size_t entries_in(const std::filesystem::path& dir) {
  size_t count = 0;
  std::error_code error;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir, error))
    ++count;
  return count;
}

// A minimal single-file NIfTI-1 image, built field by field so tests can
// break any field. Little-endian, sform only by default.
struct Nifti1Bytes {
  std::string header = std::string(352, '\0');
  std::vector<uint8_t> voxels;

  Nifti1Bytes(int16_t nx, int16_t ny, int16_t nz) {
    put<int32_t>(0, 348);
    put<int16_t>(40, 3);
    put<int16_t>(42, nx);
    put<int16_t>(44, ny);
    put<int16_t>(46, nz);
    for (int i = 4; i < 8; ++i) put<int16_t>(40 + 2 * i, 1);
    put<int16_t>(70, 2);  // uint8
    put<int16_t>(72, 8);
    put<float>(76, 1.0f);
    for (int i = 1; i < 4; ++i) put<float>(76 + 4 * i, 1.0f);
    put<float>(108, 352.0f);
    put<int16_t>(254, 1);  // sform_code
    put<float>(280, 1.0f);
    put<float>(300, 1.0f);
    put<float>(320, 1.0f);
    std::memcpy(header.data() + 344, "n+1\0", 4);
    voxels.assign(static_cast<size_t>(nx) * ny * nz, 0);
  }

  template <typename T>
  void put(size_t offset, T value) {
    std::memcpy(header.data() + offset, &value, sizeof(T));
  }

  std::string bytes() const {
    return header + std::string(reinterpret_cast<const char*>(voxels.data()), voxels.size());
  }
};

}  // namespace labelmesh::testing
