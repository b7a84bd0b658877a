// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/shared_artifacts.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::cluster {
namespace {

namespace fs = std::filesystem;

TEST(SharedArtifacts, FilesAppearWholeUnderTheirName) {
  const auto root = testing::scratch_dir("artifacts");
  auto store = SharedArtifacts::open(root.string());
  ASSERT_THAT(store, testing::IsOk());
  EXPECT_TRUE(fs::is_directory(root / "uploads"));
  EXPECT_TRUE(fs::is_directory(root / "jobs"));
  const std::string bytes(1 << 20, 'x');
  ASSERT_THAT(store->put("jobs/j1/out-1/volume.vtu", bytes), testing::IsOk());
  EXPECT_EQ(store->get("jobs/j1/out-1/volume.vtu").value(), bytes);
  // Nothing but the file itself is left in its directory.
  size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(root / "jobs/j1/out-1")) {
    EXPECT_EQ(entry.path().filename(), "volume.vtu");
    ++entries;
  }
  EXPECT_EQ(entries, 1u);
  EXPECT_EQ(store->get("jobs/j1/out-1/missing").status().code(), absl::StatusCode::kNotFound);
}

TEST(SharedArtifacts, PathsOutsideTheStoreAreRefused) {
  auto store = SharedArtifacts::open(testing::scratch_dir("artifacts-paths").string());
  ASSERT_THAT(store, testing::IsOk());
  for (const char* path : {"/etc/passwd", "../x", "jobs/../../x", ""}) {
    EXPECT_EQ(store->put(path, "x").code(), absl::StatusCode::kInvalidArgument) << path;
    EXPECT_EQ(store->get(path).status().code(), absl::StatusCode::kInvalidArgument) << path;
  }
}

TEST(SharedArtifacts, OnlyTheFinalAttemptsFilesRemain) {
  const auto root = testing::scratch_dir("artifacts-attempts");
  auto store = SharedArtifacts::open(root.string());
  ASSERT_THAT(store, testing::IsOk());
  EXPECT_EQ(store->attempt_dir("j1", 2), (root / "jobs/j1/out-2").string());
  for (int attempt : {1, 2, 3}) {
    ASSERT_THAT(store->put("jobs/j1/out-" + std::to_string(attempt) + "/report.json", "{}"),
                testing::IsOk());
  }
  EXPECT_EQ(store->remove_other_attempts("j1", 2).value(), 2u);
  EXPECT_FALSE(fs::exists(root / "jobs/j1/out-1"));
  EXPECT_TRUE(fs::exists(root / "jobs/j1/out-2/report.json"));
  EXPECT_FALSE(fs::exists(root / "jobs/j1/out-3"));
  EXPECT_EQ(store->remove_other_attempts("../x", 1).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace labelmesh::cluster
