// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/volume_header.h"

#include <algorithm>
#include <fstream>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/header/payload_stream.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume {

std::string_view scalar_type_name(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
      return "int8";
    case ScalarType::kUInt8:
      return "uint8";
    case ScalarType::kInt16:
      return "int16";
    case ScalarType::kUInt16:
      return "uint16";
    case ScalarType::kInt32:
      return "int32";
    case ScalarType::kUInt32:
      return "uint32";
    case ScalarType::kInt64:
      return "int64";
    case ScalarType::kUInt64:
      return "uint64";
    case ScalarType::kFloat32:
      return "float32";
    case ScalarType::kFloat64:
      return "float64";
  }
  return "unknown";
}

int scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUInt8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUInt16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUInt32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kInt64:
    case ScalarType::kUInt64:
    case ScalarType::kFloat64:
      return 8;
  }
  return 0;
}

uint64_t VolumeHeader::data_bytes() const {
  return static_cast<uint64_t>(geometry.voxel_count()) * static_cast<uint64_t>(layers) *
         static_cast<uint64_t>(scalar_size(scalar_type));
}

std::optional<ImageFormat> format_from_path(std::string_view path) {
  const std::string lower = to_lower(path);
  for (std::string_view ext : {".nii", ".nii.gz"}) {
    if (std::string_view(lower).ends_with(ext)) return ImageFormat::kNifti;
  }
  for (std::string_view ext : {".mha", ".mhd"}) {
    if (std::string_view(lower).ends_with(ext)) return ImageFormat::kMetaImage;
  }
  for (std::string_view ext : {".nrrd", ".nhdr"}) {
    if (std::string_view(lower).ends_with(ext)) return ImageFormat::kNrrd;
  }
  for (std::string_view ext : {".inr", ".inr.gz"}) {
    if (std::string_view(lower).ends_with(ext)) return ImageFormat::kInr;
  }
  if (std::string_view(lower).ends_with(".vti")) return ImageFormat::kVti;
  if (std::string_view(lower).ends_with(".dcm")) return ImageFormat::kDicomSeg;
  return std::nullopt;
}

bool is_dicom_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char start[132];
  if (!in.read(start, sizeof start)) return false;
  return std::string_view(start + 128, 4) == "DICM";
}

std::optional<ImageFormat> format_of_file(const std::string& path) {
  if (auto format = format_from_path(path)) return format;
  if (is_dicom_file(path)) return ImageFormat::kDicomSeg;
  return std::nullopt;
}

absl::StatusOr<VolumeHeader> check_volume_header(const std::string& path,
                                                 const ReadLimits& limits) {
  auto format = format_of_file(path);
  if (!format) {
    if (auto size = internal::file_size(path); !size.ok()) return size.status();
    return absl::InvalidArgumentError(
        cat(path,
            ": file name: unknown extension and not a DICOM file; expected .nii, .nii.gz, .mha, "
            ".mhd, .nrrd, .nhdr, .inr, .inr.gz, .vti, or a DICOM SEG (.dcm or any name)"));
  }
  if (auto size = internal::file_size(path); !size.ok()) return size.status();
  const bool gzip = std::string_view(to_lower(path)).ends_with(".gz");
  switch (*format) {
    case ImageFormat::kNifti:
      return internal::check_nifti_header(path, gzip, limits);
    case ImageFormat::kMetaImage:
      return internal::check_metaimage_header(path, limits);
    case ImageFormat::kNrrd:
      return internal::check_nrrd_header(path, limits);
    case ImageFormat::kInr:
      return internal::check_inr_header(path, gzip, limits);
    case ImageFormat::kVti:
      return internal::check_vti_header(path, limits);
    case ImageFormat::kDicomSeg:
      return internal::check_dicom_seg_volume_header(path, limits);
  }
  return absl::InternalError("unhandled image format");
}

absl::Status check_whole_payload(const VolumeHeader& header) {
  if (header.encoding == DataEncoding::kRaw) return absl::OkStatus();
  auto stream = internal::PayloadStream::open(header.data_path, header.file_offset, header.encoding,
                                              header.compressed_bytes);
  if (!stream.ok()) return stream.status();
  const uint64_t needed = header.decoded_offset + header.data_bytes();
  LABELMESH_ASSIGN_OR_RETURN(auto got, (*stream)->skip(needed));
  if (got < needed) {
    return internal::field_error(header.data_path, "voxel data",
                                 cat("is truncated: the header needs ", needed,
                                     " decoded bytes, the compressed stream holds ", got));
  }
  // Whatever follows the voxels is decoded too, so that the stream's own
  // check at its end is read; but a bomb of zeros after them is bounded.
  const uint64_t most_after = std::max<uint64_t>(needed, uint64_t{64} << 20);
  auto after = (*stream)->skip(most_after + 1);
  if (!after.ok()) return after.status();
  if (*after > most_after) {
    return internal::field_error(
        header.data_path, "compressed voxel data",
        cat("holds more than ", most_after, " bytes after the ", needed, " the header needs"));
  }
  if (!(*stream)->ended_cleanly()) {
    return internal::field_error(header.data_path, "compressed voxel data",
                                 "ends before its end-of-stream marker and checksum");
  }
  return absl::OkStatus();
}

}  // namespace labelmesh::volume
