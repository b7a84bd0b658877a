// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/spool.h"

#include <sys/statvfs.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <random>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/digest/sha256.h"
#include "core/util/status_macros.h"
#include "server/durable_file.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {
namespace fs = std::filesystem;
namespace {

constexpr const char* kRecordName = "job.pb";

absl::Status io_error(const std::string& what, const std::error_code& error) {
  spdlog::warn("spool: {}: {}", what, error.message());
  return absl::InternalError(absl::StrCat("spool: ", spool_relative(what), ": ", error.message()));
}

}  // namespace

absl::StatusOr<Spool> Spool::open(const std::string& root) {
  std::error_code error;
  fs::create_directories(fs::path(root) / "jobs", error);
  if (error) return io_error(absl::StrCat("cannot create ", root, "/jobs"), error);
  fs::remove_all(fs::path(root) / "uploads", error);
  fs::create_directories(fs::path(root) / "uploads", error);
  if (error) return io_error(absl::StrCat("cannot create ", root, "/uploads"), error);
  fs::create_directories(fs::path(root) / "quarantine", error);
  if (error) return io_error(absl::StrCat("cannot create ", root, "/quarantine"), error);
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

std::string Spool::output_dir(const std::string& job_id, uint32_t attempt) const {
  return absl::StrCat(job_dir(job_id), "/out-", attempt);
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
  absl::Status status = save(record);
  if (status.ok()) status = sync_directory(absl::StrCat(root_, "/jobs"));
  if (!status.ok()) fs::remove_all(dir, error);
  return status;
}

absl::Status Spool::save(const v1::JobRecord& record) const {
  const std::string dir = job_dir(record.job().job_id());
  const std::string final_path = absl::StrCat(dir, "/", kRecordName);
  const std::string temporary = final_path + ".tmp";
  std::string bytes;
  if (!record.SerializeToString(&bytes))
    return absl::InternalError(absl::StrCat("spool: cannot serialise the record of ", dir));
  // The old record stays until the new one is whole on disk.
  std::error_code error;
  if (auto status = write_file_synced(temporary, bytes); !status.ok()) {
    fs::remove(temporary, error);
    return status;
  }
  fs::rename(temporary, final_path, error);
  if (error) return io_error(absl::StrCat("cannot replace ", final_path), error);
  return sync_directory(dir);
}

std::vector<v1::JobRecord> Spool::load_all() const {
  std::vector<v1::JobRecord> records;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(fs::path(root_) / "jobs", error)) {
    const std::string name = entry.path().filename().string();
    const fs::path record_path = entry.path() / kRecordName;
    if (is_job_id(name) && !fs::exists(record_path, error)) {
      // Never got an "accepted" reply: its record was not written yet.
      fs::remove_all(entry.path(), error);
      continue;
    }
    v1::JobRecord record;
    std::ifstream in(record_path, std::ios::binary);
    if (is_job_id(name) && in && record.ParseFromIstream(&in) && record.job().job_id() == name) {
      records.push_back(std::move(record));
    } else {
      quarantine(entry.path().string());
    }
  }
  return records;
}

void Spool::quarantine(const std::string& path) const {
  // An unreadable record may still be somebody's accepted job: kept aside
  // for a person to look at, never deleted. Only the directory's name is
  // logged; the name of anything not a job id is not.
  const std::string name = fs::path(path).filename().string();
  const std::string target =
      absl::StrCat(root_, "/quarantine/", is_job_id(name) ? name : "entry", "-", new_job_id());
  std::error_code error;
  fs::rename(path, target, error);
  if (error) {
    spdlog::error("spool: unreadable entry {} could not be quarantined: {}",
                  is_job_id(name) ? name : "(not a job id)", error.message());
  } else {
    spdlog::error("spool: unreadable job record {} moved to {}",
                  is_job_id(name) ? name : "(not a job id)", target);
  }
}

absl::StatusOr<uint64_t> Spool::free_bytes() const {
  struct statvfs figures {};
  if (::statvfs(root_.c_str(), &figures) != 0)
    return spool_io_error(absl::StrCat("cannot read the free space of ", root_), errno);
  return uint64_t(figures.f_bavail) * figures.f_frsize;
}

void Spool::remove_job(const std::string& job_id) const {
  std::error_code error;
  fs::remove_all(job_dir(job_id), error);
}

void Spool::remove_input(const v1::JobRecord& record) const {
  std::error_code error;
  fs::remove(input_path(record), error);
}

absl::Status Spool::reset_output(const std::string& job_id, uint32_t attempt) const {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(job_dir(job_id), error)) {
    const std::string name = entry.path().filename().string();
    if (name == "out" || absl::StartsWith(name, "out-")) fs::remove_all(entry.path(), error);
  }
  error.clear();
  fs::create_directories(output_dir(job_id, attempt), error);
  if (error) return io_error("cannot create the output directory", error);
  return absl::OkStatus();
}

void Spool::adopt_output(const std::string& job_id, uint32_t attempt) const {
  const fs::path old = fs::path(job_dir(job_id)) / "out";
  std::error_code error;
  if (fs::is_directory(old, error)) fs::rename(old, output_dir(job_id, attempt), error);
}

absl::StatusOr<std::vector<v1::Artifact>> Spool::collect_artifacts(const std::string& job_id,
                                                                   uint32_t attempt) const {
  return list_artifacts(output_dir(job_id, attempt));
}

absl::StatusOr<std::vector<v1::Artifact>> list_artifacts(const std::string& dir) {
  std::vector<v1::Artifact> artifacts;
  const fs::path out = dir;
  // Without exceptions: a stale attempt's folder can be removed while it is
  // listed, and that is an error for the attempt, not a crash of the worker.
  std::error_code error;
  for (fs::recursive_directory_iterator it(out, error), end; !error && it != end;
       it.increment(error)) {
    const fs::directory_entry& entry = *it;
    if (!entry.is_regular_file(error)) {
      if (error) break;
      continue;
    }
    const uintmax_t size = entry.file_size(error);
    if (error) break;
    v1::Artifact artifact;
    artifact.set_name(entry.path().lexically_relative(out).string());
    artifact.set_size_bytes(size);
    LABELMESH_ASSIGN_OR_RETURN(auto digest, digest::sha256_file(entry.path().string()));
    artifact.set_sha256(digest);
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
