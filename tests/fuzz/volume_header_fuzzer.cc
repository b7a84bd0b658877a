// SPDX-License-Identifier: AGPL-3.0-or-later
// Fuzzes every volume header parser through check_volume_header, then
// check_whole_payload on what it accepts. The first byte picks the file name
// extension (and so the parser) and whether a separate data file is allowed;
// the other bytes are the file. An accepted header must keep its contract.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iterator>

#include "core/header/volume_header.h"
#include "fuzz/fuzz_support.h"

namespace {

using labelmesh::fuzzing::contract_broken;

constexpr const char* kExtensions[] = {".nii",  ".nii.gz", ".mha",    ".mhd", ".nrrd",
                                       ".nhdr", ".inr",    ".inr.gz", ".vti"};
// Small enough that a compressed payload decodes in well under a second.
constexpr uint64_t kMaxVoxels = uint64_t{1} << 24;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace volume = labelmesh::volume;
  if (size < 1 || size > labelmesh::fuzzing::kMaxInputBytes) return 0;
  const char* extension = kExtensions[(data[0] & 0x7f) % std::size(kExtensions)];
  volume::ReadLimits limits;
  limits.max_voxels = kMaxVoxels;
  limits.allow_data_file = (data[0] & 0x80) != 0;
  const labelmesh::fuzzing::ScratchFile file(extension, data + 1, size - 1);

  auto header = volume::check_volume_header(file.path(), limits);
  if (!header.ok()) return 0;
  labelmesh::fuzzing::check_geometry_contract(header->geometry, kMaxVoxels);
  if (header->format != volume::format_from_path(file.path()))
    contract_broken("format differs from the extension");
  if (!limits.allow_data_file && header->data_path != file.path())
    contract_broken("a data file other than the header, though none is allowed");
  if (!std::isfinite(header->rescale_slope) || header->rescale_slope == 0 ||
      !std::isfinite(header->rescale_intercept))
    contract_broken("rescaling not finite");
  if (header->format != volume::ImageFormat::kVti &&
      header->encoding == volume::DataEncoding::kRaw) {
    // VTI payloads are left to VTK's reader; every other raw payload was
    // measured against its file.
    std::error_code error;
    const uint64_t bytes = std::filesystem::file_size(header->data_path, error);
    if (error || header->file_offset > bytes || bytes - header->file_offset < header->data_bytes())
      contract_broken("raw voxels past the end of their file");
  }
  (void)volume::check_whole_payload(*header);
  return 0;
}
