// SPDX-License-Identifier: AGPL-3.0-or-later
// Files the spool writes: every write, fsync and close checked, so a full
// disk is an error the caller sees, never a short file that looks whole.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh::server {

// RESOURCE_EXHAUSTED "spool disk full: ..." for ENOSPC, EDQUOT and EFBIG,
// INTERNAL "spool: ..." otherwise; `what` says which file and what was done.
// The status, which clients may see, names files only from their jobs/,
// uploads/ or quarantine/ folder on (spool_relative); the log names them whole.
absl::Status spool_io_error(const std::string& what, int error_number);

// `text` with every absolute path in it cut to the part a client may see:
// from its jobs/, uploads/ or quarantine/ component on, else its file name.
std::string spool_relative(std::string_view text);

class FileWriter {
 public:
  FileWriter() = default;
  FileWriter(const FileWriter&) = delete;
  FileWriter& operator=(const FileWriter&) = delete;
  // Closes an unfinished file without syncing it.
  ~FileWriter();

  // Creates or truncates `path` (mode 0600).
  absl::Status open(const std::string& path);
  absl::Status append(std::string_view bytes);
  // fsync and close; the file is whole on disk once this returns OK.
  absl::Status finish();

 private:
  std::string path_;
  int fd_ = -1;
};

// Writes `bytes` to `path` through a FileWriter.
absl::Status write_file_synced(const std::string& path, std::string_view bytes);
// fsync of a directory, so that a rename or a new entry in it is on disk.
absl::Status sync_directory(const std::string& path);

}  // namespace labelmesh::server
