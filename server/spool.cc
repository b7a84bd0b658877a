// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/spool.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include "absl/strings/str_cat.h"
#include "server/sha256.h"

namespace labelmesh::server {
namespace fs = std::filesystem;
namespace {

constexpr const char* kRecordName = "job.pb";

// fsync a file or directory so a rename or write survives a power cut.
void sync_path(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

absl::Status io_error(const std::string& what, const std::error_code& error) {
  return absl::InternalError(absl::StrCat("spool: ", what, ": ", error.message()));
}

}  // namespace

absl::StatusOr<Spool> Spool::open(const std::string& root) {
  std::error_code error;
  fs::create_directories(fs::path(root) / "jobs", error);
  if (error) return io_error(absl::StrCat("cannot create ", root, "/jobs"), error);
  fs::remove_all(fs::path(root) / "uploads", error);
  fs::create_directories(fs::path(root) / "uploads", error);
  if (error) return io_error(absl::StrCat("cannot create ", root, "/uploads"), error);
  return Spool(fs::absolute(root).string());
}

std::string Spool::upload_path(const std::string& job_id, const std::string& extension) const {
  return absl::StrCat(root_, "/uploads/", job_id, extension);
}

std::string Spool::job_dir(const std::string& job_id) const {
  return absl::StrCat(root_, "/jobs/", job_id);
}

std::string Spool::input_path(const v1::JobRecord& record) const {
  return absl::StrCat(job_dir(record.job().job_id()), "/input", record.input_extension());
}

std::string Spool::output_dir(const std::string& job_id) const {
  return absl::StrCat(job_dir(job_id), "/out");
}

std::string Spool::worker_log(const std::string& job_id) const {
  return absl::StrCat(job_dir(job_id), "/worker.log");
}

absl::Status Spool::create_job(const v1::JobRecord& record, const std::string& upload_path) const {
  const std::string dir = job_dir(record.job().job_id());
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) return io_error(absl::StrCat("cannot create ", dir), error);
  fs::rename(upload_path, input_path(record), error);
  if (error) return io_error("cannot move the upload into its job", error);
  if (auto status = save(record); !status.ok()) {
    fs::remove_all(dir, error);
    return status;
  }
  sync_path(absl::StrCat(root_, "/jobs"));
  return absl::OkStatus();
}

absl::Status Spool::save(const v1::JobRecord& record) const {
  const std::string dir = job_dir(record.job().job_id());
  const std::string final_path = absl::StrCat(dir, "/", kRecordName);
  const std::string temporary = final_path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out || !record.SerializeToOstream(&out)) {
      return absl::InternalError(absl::StrCat("spool: cannot write ", temporary));
    }
  }
  sync_path(temporary);
  std::error_code error;
  fs::rename(temporary, final_path, error);
  if (error) return io_error(absl::StrCat("cannot replace ", final_path), error);
  sync_path(dir);
  return absl::OkStatus();
}

std::vector<v1::JobRecord> Spool::load_all() const {
  std::vector<v1::JobRecord> records;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(fs::path(root_) / "jobs", error)) {
    const std::string name = entry.path().filename().string();
    v1::JobRecord record;
    std::ifstream in(entry.path() / kRecordName, std::ios::binary);
    const bool readable =
        is_job_id(name) && in && record.ParseFromIstream(&in) && record.job().job_id() == name;
    if (readable) {
      records.push_back(std::move(record));
    } else {
      // A job directory without its record never got an "accepted" reply.
      fs::remove_all(entry.path(), error);
    }
  }
  return records;
}

void Spool::remove_job(const std::string& job_id) const {
  std::error_code error;
  fs::remove_all(job_dir(job_id), error);
}

absl::Status Spool::reset_output(const std::string& job_id) const {
  std::error_code error;
  fs::remove_all(output_dir(job_id), error);
  fs::create_directories(output_dir(job_id), error);
  if (error) return io_error("cannot create the output directory", error);
  return absl::OkStatus();
}

absl::StatusOr<std::vector<v1::Artifact>> Spool::collect_artifacts(
    const std::string& job_id) const {
  std::vector<v1::Artifact> artifacts;
  const fs::path out = output_dir(job_id);
  std::error_code error;
  for (const auto& entry : fs::recursive_directory_iterator(out, error)) {
    if (!entry.is_regular_file()) continue;
    v1::Artifact artifact;
    artifact.set_name(fs::relative(entry.path(), out).string());
    artifact.set_size_bytes(entry.file_size());
    auto digest = digest::sha256_file(entry.path().string());
    if (!digest.ok()) return digest.status();
    artifact.set_sha256(*digest);
    artifacts.push_back(std::move(artifact));
  }
  if (error) return io_error("cannot list the results", error);
  std::sort(artifacts.begin(), artifacts.end(),
            [](const auto& a, const auto& b) { return a.name() < b.name(); });
  return artifacts;
}

std::string new_job_id() {
  static constexpr char kHex[] = "0123456789abcdef";
  std::random_device random;
  std::string id;
  for (int i = 0; i < 32; ++i) id.push_back(kHex[random() & 15]);
  return id;
}

bool is_job_id(std::string_view text) { return digest::is_lower_hex(text, 32); }

}  // namespace labelmesh::server
