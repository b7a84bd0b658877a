// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/upload_checks.h"

#include <algorithm>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/digest/sha256.h"
#include "core/header/volume_header.h"
#include "core/job/job_options.h"
#include "server/refusal.h"

namespace labelmesh::server {

absl::StatusOr<std::string> upload_extension(const std::string& file_name) {
  // Longest first: ".nii.gz" before ".nii" could never match it anyway, but
  // ".gz" alone must not pass.
  for (const char* extension :
       {".nii.gz", ".inr.gz", ".nii", ".mha", ".nrrd", ".inr", ".vti", ".dcm"}) {
    if (absl::EndsWithIgnoreCase(file_name, extension)) return std::string(extension);
  }
  return absl::InvalidArgumentError(
      "spec.file_name: unknown or unsupported extension; uploads are single files: .nii, "
      ".nii.gz, .mha, .nrrd, .inr, .inr.gz, .vti or .dcm (DICOM SEG)");
}

absl::StatusOr<MeshParams> check_spec(const v1::JobSpec& spec, const ServerConfig& config) {
  if (auto extension = upload_extension(spec.file_name()); !extension.ok()) {
    return extension.status();
  }
  if (spec.size_bytes() == 0)
    return absl::InvalidArgumentError("spec.size_bytes: must be positive");
  if (spec.size_bytes() > config.max_upload_bytes) {
    return refused(Refusal::kTooLarge,
                   absl::InvalidArgumentError(absl::StrCat("spec.size_bytes: ", spec.size_bytes(),
                                                           " is over the server's upload limit of ",
                                                           config.max_upload_bytes, " bytes")));
  }
  if (!digest::is_sha256_hex(spec.sha256())) {
    return absl::InvalidArgumentError("spec.sha256: must be 64 lowercase hex digits");
  }
  if (spec.request_id().size() > 128 ||
      !std::all_of(spec.request_id().begin(), spec.request_id().end(),
                   [](char c) { return c >= 0x21 && c <= 0x7e; })) {
    return absl::InvalidArgumentError(
        "spec.request_id: must be at most 128 printable ASCII characters, no spaces");
  }
  auto params = params_from_options(spec.options());
  if (!params.ok())
    return absl::InvalidArgumentError(absl::StrCat("spec.options: ", params.status().message()));
  return params;
}

absl::StatusOr<volume::ImageGeometry> check_uploaded_volume(const std::string& path,
                                                            uint64_t max_voxels,
                                                            uint64_t worker_memory_bytes) {
  volume::ReadLimits limits;
  limits.max_voxels = max_voxels;
  limits.allow_data_file = false;
  auto as_upload = [&](const absl::Status& status) {
    return absl::Status(status.code(), absl::StrReplaceAll(status.message(), {{path, "upload"}}));
  };
  auto header = volume::check_volume_header(path, limits);
  if (!header.ok()) return as_upload(header.status());
  // What a worker holds at the least: the voxels as stored, and one byte per
  // voxel for a label's mask. A job above that fails in its worker anyway.
  const uint64_t voxels = uint64_t(header->geometry.voxel_count());
  const uint64_t least_bytes = header->data_bytes() + voxels;
  if (worker_memory_bytes > 0 && least_bytes > worker_memory_bytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "upload: ", voxels, " voxels of ",
        std::string(volume::scalar_type_name(header->scalar_type)), " need at least ", least_bytes,
        " bytes in a worker; the server's worker limit is ", worker_memory_bytes, " bytes"));
  }
  if (auto status = volume::check_whole_payload(*header); !status.ok()) return as_upload(status);
  return header->geometry;
}

}  // namespace labelmesh::server
