// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/durable_file.h"

#include "core/util/status_macros.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "server/refusal.h"
#include "spdlog/spdlog.h"

namespace labelmesh::server {

std::string spool_relative(std::string_view text) {
  std::string out;
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = std::min(text.find(' ', at), text.size());
    std::string_view word = text.substr(at, end - at);
    if (!word.empty() && word.front() == '/') {
      size_t keep = std::string_view::npos;
      for (std::string_view part : {"/jobs/", "/uploads/", "/quarantine/"})
        if (const size_t found = word.rfind(part);
            found != std::string_view::npos && (keep == std::string_view::npos || found > keep))
          keep = found;
      word =
          keep != std::string_view::npos ? word.substr(keep + 1) : word.substr(word.rfind('/') + 1);
    }
    out.append(word);
    if (end < text.size()) out.push_back(' ');
    at = end + 1;
  }
  return out;
}

absl::Status spool_io_error(const std::string& what, int error_number) {
  spdlog::warn("spool: {}: {}", what, std::strerror(error_number));
  const std::string shown = spool_relative(what);
  if (error_number == ENOSPC || error_number == EDQUOT || error_number == EFBIG) {
    return refused(Refusal::kDiskFull,
                   absl::ResourceExhaustedError(absl::StrCat("spool disk full: ", shown, ": ",
                                                             std::strerror(error_number))));
  }
  return refused(Refusal::kSpoolError, absl::InternalError(absl::StrCat(
                                           "spool: ", shown, ": ", std::strerror(error_number))));
}

FileWriter::~FileWriter() {
  if (fd_ >= 0) ::close(fd_);
}

absl::Status FileWriter::open(const std::string& path) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd_ < 0) return spool_io_error(absl::StrCat("cannot create ", path), errno);
  return absl::OkStatus();
}

absl::Status FileWriter::append(std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return spool_io_error(absl::StrCat("cannot write ", path_), errno);
    bytes.remove_prefix(size_t(n));
  }
  return absl::OkStatus();
}

absl::Status FileWriter::finish() {
  // Delayed allocation can report a full disk only here.
  if (::fsync(fd_) != 0) return spool_io_error(absl::StrCat("cannot sync ", path_), errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) return spool_io_error(absl::StrCat("cannot close ", path_), errno);
  return absl::OkStatus();
}

absl::Status write_file_synced(const std::string& path, std::string_view bytes) {
  FileWriter file;
  LABELMESH_RETURN_IF_ERROR(file.open(path));
  LABELMESH_RETURN_IF_ERROR(file.append(bytes));
  return file.finish();
}

absl::Status sync_directory(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return spool_io_error(absl::StrCat("cannot open ", path), errno);
  const int synced = ::fsync(fd);
  const int error_number = errno;
  ::close(fd);
  if (synced != 0) return spool_io_error(absl::StrCat("cannot sync ", path), error_number);
  return absl::OkStatus();
}

}  // namespace labelmesh::server
