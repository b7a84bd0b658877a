// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/cluster/shared_artifacts.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"

namespace labelmesh::cluster {

namespace fs = std::filesystem;

absl::StatusOr<SharedArtifacts> SharedArtifacts::open(const std::string& root) {
  std::error_code error;
  for (const char* sub : {"uploads", "jobs"}) {
    fs::create_directories(fs::path(root) / sub, error);
    if (error) {
      return absl::InternalError(
          absl::StrCat("artifact store ", root, ": cannot create ", sub, ": ", error.message()));
    }
  }
  return SharedArtifacts(fs::weakly_canonical(root).string());
}

std::string SharedArtifacts::job_dir(const std::string& job_id) const {
  return (fs::path(root_) / "jobs" / job_id).string();
}

std::string SharedArtifacts::attempt_dir(const std::string& job_id, uint32_t attempt) const {
  return (fs::path(job_dir(job_id)) / absl::StrCat("out-", attempt)).string();
}

absl::StatusOr<uint64_t> SharedArtifacts::free_bytes() const {
  std::error_code error;
  const fs::space_info space = fs::space(root_, error);
  if (error)
    return server::spool_io_error(absl::StrCat("cannot read the free space of ", root_),
                                  error.value());
  return space.available;
}

void SharedArtifacts::remove_job(const std::string& job_id) const {
  std::error_code ignored;
  fs::remove_all(job_dir(job_id), ignored);
}

absl::StatusOr<std::string> SharedArtifacts::resolve(std::string_view relative) const {
  const fs::path path(relative);
  if (relative.empty() || path.is_absolute()) {
    return absl::InvalidArgumentError(
        absl::StrCat("artifact path '", std::string(relative), "' is not relative to the store"));
  }
  for (const auto& part : path) {
    if (part == "..") {
      return absl::InvalidArgumentError(
          absl::StrCat("artifact path '", std::string(relative), "' leaves the store"));
    }
  }
  return (fs::path(root_) / path).string();
}

absl::Status SharedArtifacts::put(std::string_view relative, std::string_view bytes) const {
  LABELMESH_ASSIGN_OR_RETURN(auto path, resolve(relative));
  const fs::path target(path);
  std::error_code error;
  fs::create_directories(target.parent_path(), error);
  if (error) return server::spool_io_error(target.parent_path().string(), error.value());
  // A hidden name unique to this writer: two workers never share it.
  std::random_device random;
  const fs::path partial = target.parent_path() / absl::StrCat(".", target.filename().string(), ".",
                                                               getpid(), ".", random(), ".partial");
  if (auto status = server::write_file_synced(partial.string(), bytes); !status.ok()) {
    fs::remove(partial, error);
    return status;
  }
  fs::rename(partial, target, error);
  if (error) {
    fs::remove(partial, error);
    return server::spool_io_error(target.string(), error.value());
  }
  return server::sync_directory(target.parent_path().string());
}

absl::StatusOr<std::string> SharedArtifacts::get(std::string_view relative) const {
  LABELMESH_ASSIGN_OR_RETURN(auto path, resolve(relative));
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return absl::NotFoundError(absl::StrCat("artifact ", std::string(relative), " not found"));
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

absl::StatusOr<size_t> SharedArtifacts::remove_other_attempts(const std::string& job_id,
                                                              uint32_t kept) const {
  LABELMESH_ASSIGN_OR_RETURN(auto job_dir, resolve(absl::StrCat("jobs/", job_id)));
  const std::string keep = absl::StrCat("out-", kept);
  size_t removed = 0;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(job_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("out-", 0) != 0 || name == keep) continue;
    fs::remove_all(entry.path(), error);
    if (error) return server::spool_io_error(entry.path().string(), error.value());
    ++removed;
  }
  return removed;
}

}  // namespace labelmesh::cluster
