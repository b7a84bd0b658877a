// SPDX-License-Identifier: AGPL-3.0-or-later
// INRIMAGE-4 header checks. The header is "#INRIMAGE-4#{", KEY=VALUE lines,
// newline padding to a multiple of 256 bytes, and "##}"; the voxels follow,
// and .inr.gz compresses header and voxels together. INR has no anatomical
// frame: the grid is axis-aligned and taken as LPS, origin from TX/TY/TZ
// (CGAL's translation keys) when present.
#include <cmath>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/header/text_header.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

constexpr std::string_view kMagic = "#INRIMAGE-4#{";
constexpr std::string_view kEnd = "##}\n";

absl::StatusOr<double> number_field(const std::string& path, const TextHeader& h,
                                    std::string_view key, std::optional<double> fallback) {
  auto value = h.find(key);
  if (!value) {
    if (fallback) return *fallback;
    return field_error(path, key, "is missing");
  }
  LABELMESH_ASSIGN_OR_RETURN(auto parsed, parse_numbers(path, key, *value, 1));
  return parsed[0];
}

}  // namespace

absl::StatusOr<VolumeHeader> check_inr_header(const std::string& path, bool gzip,
                                              const ReadLimits& limits) {
  auto bytes = read_prefix(path, limits.max_header_bytes, gzip);
  if (!bytes.ok()) return bytes.status();
  if (!std::string_view(*bytes).starts_with(kMagic)) {
    return field_error(path, "magic", "the file does not start with #INRIMAGE-4#{");
  }
  const size_t end = bytes->find(kEnd);
  if (end == std::string::npos) {
    return field_error(path, "header", cat("has no ##} end line within ", bytes->size(), " bytes"));
  }
  const uint64_t header_size = end + kEnd.size();
  if (header_size % 256 != 0) {
    return field_error(path, "header",
                       cat("is ", header_size, " bytes; INR headers are a multiple of 256"));
  }
  LABELMESH_ASSIGN_OR_RETURN(
      auto text,
      parse_text_header(path, std::string_view(*bytes).substr(0, end),
                        {.separator = "=", .comment = "#", .last_key = "", .key_value_marker = ""},
                        end + 1));
  const TextHeader& h = text;

  std::array<int64_t, 3> dims{};
  const char* dim_keys[3] = {"XDIM", "YDIM", "ZDIM"};
  for (int axis = 0; axis < 3; ++axis) {
    LABELMESH_ASSIGN_OR_RETURN(auto value, number_field(path, h, dim_keys[axis], std::nullopt));
    if (value != std::floor(value) || value < 1 || value > 1e12) {
      return field_error(path, dim_keys[axis], "must be a whole number >= 1");
    }
    dims[axis] = static_cast<int64_t>(value);
  }
  LABELMESH_RETURN_IF_ERROR(check_dims(path, "XDIM/YDIM/ZDIM", dims, limits));
  LABELMESH_ASSIGN_OR_RETURN(auto vdim, number_field(path, h, "VDIM", 1.0));
  if (vdim != 1) return field_error(path, "VDIM", "must be 1 for a label volume");

  auto type = h.find("TYPE");
  auto pixsize = h.find("PIXSIZE");
  if (!type) return field_error(path, "TYPE", "is missing");
  if (!pixsize) return field_error(path, "PIXSIZE", "is missing");
  const int bits = *pixsize == "8 bits"    ? 8
                   : *pixsize == "16 bits" ? 16
                   : *pixsize == "32 bits" ? 32
                   : *pixsize == "64 bits" ? 64
                                           : 0;
  if (bits == 0) return field_error(path, "PIXSIZE", "must be 8, 16, 32 or 64 bits");
  ScalarType scalar;
  if (*type == "unsigned fixed") {
    scalar = bits == 8    ? ScalarType::kUInt8
             : bits == 16 ? ScalarType::kUInt16
             : bits == 32 ? ScalarType::kUInt32
                          : ScalarType::kUInt64;
  } else if (*type == "signed fixed") {
    scalar = bits == 8    ? ScalarType::kInt8
             : bits == 16 ? ScalarType::kInt16
             : bits == 32 ? ScalarType::kInt32
                          : ScalarType::kInt64;
  } else if (*type == "float") {
    if (bits != 32 && bits != 64)
      return field_error(path, "PIXSIZE", "float voxels need 32 or 64 bits");
    scalar = bits == 32 ? ScalarType::kFloat32 : ScalarType::kFloat64;
  } else {
    return field_error(path, "TYPE", "must be unsigned fixed, signed fixed or float");
  }

  VolumeHeader header;
  header.format = ImageFormat::kInr;
  header.scalar_type = scalar;
  if (auto cpu = h.find("CPU")) {
    if (*cpu == "decm" || *cpu == "alpha" || *cpu == "pc") {
      header.big_endian = false;
    } else if (*cpu == "sun" || *cpu == "sgi") {
      header.big_endian = true;
    } else {
      return field_error(path, "CPU", "must be decm, alpha, pc, sun or sgi");
    }
  }
  ImageGeometry& g = header.geometry;
  g.dims = dims;
  const char* spacing_keys[3] = {"VX", "VY", "VZ"};
  const char* origin_keys[3] = {"TX", "TY", "TZ"};
  for (int axis = 0; axis < 3; ++axis) {
    LABELMESH_ASSIGN_OR_RETURN(auto spacing, number_field(path, h, spacing_keys[axis], 1.0));
    g.spacing[axis] = spacing;
    LABELMESH_ASSIGN_OR_RETURN(auto origin, number_field(path, h, origin_keys[axis], 0.0));
    g.origin[axis] = origin;
  }
  LABELMESH_RETURN_IF_ERROR(check_spacing(path, "VX/VY/VZ", g.spacing));

  header.data_path = path;
  header.encoding = gzip ? DataEncoding::kGzip : DataEncoding::kRaw;
  header.file_offset = gzip ? 0 : header_size;
  header.decoded_offset = gzip ? header_size : 0;
  const uint64_t needed = header.data_bytes();
  auto payload = gzip ? check_encoded_payload(path, 0, DataEncoding::kGzip, 0, header_size + needed)
                      : check_raw_payload(path, header_size, needed);
  if (!payload.ok()) return payload;
  return header;
}

}  // namespace labelmesh::volume::internal
