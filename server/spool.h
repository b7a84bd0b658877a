// SPDX-License-Identifier: AGPL-3.0-or-later
// The spool directory: every accepted job and its files, on disk before the
// client hears "accepted", so that a crash or restart loses nothing.
//
//   <root>/uploads/<id><ext>      an upload being received (wiped at start)
//   <root>/jobs/<id>/job.pb       the JobRecord, replaced atomically
//   <root>/jobs/<id>/input<ext>   the uploaded volume, until the job ends
//                                 (unless the client asked to keep it)
//   <root>/jobs/<id>/out-<n>/     meshes and report.json of attempt n: a
//                                 stale worker of an earlier attempt can
//                                 never write over a later one's results
//   <root>/jobs/<id>/worker.log   the worker's stderr
//   <root>/quarantine/            job directories whose record could not be
//                                 read, kept for a person to look at
//
// A write that fails leaves the previous record in place; a full disk is
// RESOURCE_EXHAUSTED "spool disk full".
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "labelmesh/v1/service.pb.h"

namespace labelmesh::server {

class Spool {
 public:
  // Creates the directories and wipes unfinished uploads.
  static absl::StatusOr<Spool> open(const std::string& root);

  const std::string& root() const { return root_; }
  std::string upload_path(const std::string& job_id, const std::string& extension) const;
  std::string job_dir(const std::string& job_id) const;
  std::string input_path(const v1::JobRecord& record) const;
  std::string output_dir(const std::string& job_id, uint32_t attempt) const;
  std::string worker_log(const std::string& job_id) const;

  // Makes the job directory, moves the upload in and writes the record.
  absl::Status create_job(const v1::JobRecord& record, const std::string& upload_path) const;
  // Replaces job.pb atomically (temporary file, fsync, rename, fsync).
  absl::Status save(const v1::JobRecord& record) const;
  // Every job directory with a readable record. One without a record (never
  // accepted) is removed; one whose record is unreadable is quarantined.
  std::vector<v1::JobRecord> load_all() const;
  void remove_job(const std::string& job_id) const;
  // Deletes the job's input (once it ended, unless the client kept it).
  void remove_input(const v1::JobRecord& record) const;
  // Before an attempt: removes the output of earlier attempts and makes an
  // empty one for this attempt.
  absl::Status reset_output(const std::string& job_id, uint32_t attempt) const;
  // Moves the results of a spool written before attempts had directories
  // of their own (out/) to the attempt's (out-<n>/).
  void adopt_output(const std::string& job_id, uint32_t attempt) const;
  // list_artifacts of the attempt's output.
  absl::StatusOr<std::vector<v1::Artifact>> collect_artifacts(const std::string& job_id,
                                                              uint32_t attempt) const;
  // Bytes an unprivileged writer may still use on the spool's file system.
  absl::StatusOr<uint64_t> free_bytes() const;

 private:
  void quarantine(const std::string& path) const;
  explicit Spool(std::string root) : root_(std::move(root)) {}
  std::string root_;
};

// Every regular file under `dir`, named relative to it, with size and
// SHA-256, sorted by name.
absl::StatusOr<std::vector<v1::Artifact>> list_artifacts(const std::string& dir);

// A fresh job id: 32 random lowercase hex digits.
std::string new_job_id();
// True for what new_job_id() makes; anything else never reaches a path.
bool is_job_id(std::string_view text);

}  // namespace labelmesh::server
