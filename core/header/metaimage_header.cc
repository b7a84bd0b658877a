// SPDX-License-Identifier: AGPL-3.0-or-later
// MetaImage (.mha/.mhd) header checks. Keys follow MetaIO; TransformMatrix
// lists the direction of voxel axis 0, then 1, then 2 (as ITK reads it), in
// LPS, which is MetaImage's (ITK's) frame.
#include <cmath>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/header/text_header.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

absl::StatusOr<ScalarType> metaimage_scalar_type(const std::string& path, std::string_view name) {
  struct Known {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Known kKnown[] = {
      {"MET_CHAR", ScalarType::kInt8},       {"MET_UCHAR", ScalarType::kUInt8},
      {"MET_SHORT", ScalarType::kInt16},     {"MET_USHORT", ScalarType::kUInt16},
      {"MET_INT", ScalarType::kInt32},       {"MET_UINT", ScalarType::kUInt32},
      {"MET_LONG", ScalarType::kInt32},      {"MET_ULONG", ScalarType::kUInt32},
      {"MET_LONG_LONG", ScalarType::kInt64}, {"MET_ULONG_LONG", ScalarType::kUInt64},
      {"MET_FLOAT", ScalarType::kFloat32},   {"MET_DOUBLE", ScalarType::kFloat64}};
  for (const auto& known : kKnown) {
    if (known.name == name) return known.type;
  }
  return field_error(path, "ElementType", "is not an integer or real scalar MET_ type");
}

// A MetaImage boolean; nullopt when the value is neither true nor false.
std::optional<bool> metaimage_bool(std::string_view value) {
  if (equals_ignore_case(value, "true") || value == "1") return true;
  if (equals_ignore_case(value, "false") || value == "0") return false;
  return std::nullopt;
}

absl::StatusOr<bool> optional_bool(const std::string& path, const TextHeader& header,
                                   std::string_view key, bool fallback) {
  auto value = header.find(key);
  if (!value) return fallback;
  auto parsed = metaimage_bool(*value);
  if (!parsed) return field_error(path, key, "is neither True nor False");
  return *parsed;
}

// The first of `keys` present, parsed as `count` numbers, or `fallback`.
absl::StatusOr<std::vector<double>> numbers_of(const std::string& path, const TextHeader& header,
                                               std::initializer_list<std::string_view> keys,
                                               size_t count, std::vector<double> fallback) {
  for (auto key : keys) {
    if (auto value = header.find(key)) return parse_numbers(path, key, *value, count);
  }
  return fallback;
}

}  // namespace

absl::StatusOr<VolumeHeader> check_metaimage_header(const std::string& path,
                                                    const ReadLimits& limits) {
  auto bytes = read_prefix(path, limits.max_header_bytes, false);
  if (!bytes.ok()) return bytes.status();
  LABELMESH_ASSIGN_OR_RETURN(
      auto text,
      parse_text_header(
          path, *bytes,
          {.separator = "=", .comment = "", .last_key = "ElementDataFile", .key_value_marker = ""},
          limits.max_header_bytes));
  const TextHeader& h = text;

  if (auto type = h.find("ObjectType"); type && !equals_ignore_case(*type, "Image")) {
    return field_error(path, "ObjectType", "is not Image");
  }
  auto ndims = h.find("NDims");
  if (!ndims || *ndims != "3") return field_error(path, "NDims", "must be 3");
  auto dim_text = h.find("DimSize");
  if (!dim_text) return field_error(path, "DimSize", "is missing");
  LABELMESH_ASSIGN_OR_RETURN(auto dim_values, parse_numbers(path, "DimSize", *dim_text, 3));
  LABELMESH_ASSIGN_OR_RETURN(auto whole, whole_sizes(path, "DimSize", dim_values));
  const std::array<int64_t, 3> dims = whole;
  LABELMESH_RETURN_IF_ERROR(check_dims(path, "DimSize", dims, limits));

  auto element_type = h.find("ElementType");
  if (!element_type) return field_error(path, "ElementType", "is missing");
  LABELMESH_ASSIGN_OR_RETURN(auto type, metaimage_scalar_type(path, *element_type));
  if (auto channels = h.find("ElementNumberOfChannels"); channels && *channels != "1") {
    return field_error(path, "ElementNumberOfChannels", "must be 1 for a label volume");
  }
  LABELMESH_ASSIGN_OR_RETURN(auto binary, optional_bool(path, h, "BinaryData", true));
  if (!binary) return field_error(path, "BinaryData", "ASCII voxel data is not supported");

  LABELMESH_ASSIGN_OR_RETURN(auto spacing,
                             numbers_of(path, h, {"ElementSpacing", "ElementSize"}, 3, {1, 1, 1}));
  LABELMESH_ASSIGN_OR_RETURN(auto origin,
                             numbers_of(path, h, {"Offset", "Origin", "Position"}, 3, {0, 0, 0}));
  LABELMESH_ASSIGN_OR_RETURN(auto matrix,
                             numbers_of(path, h, {"TransformMatrix", "Rotation", "Orientation"}, 9,
                                        {1, 0, 0, 0, 1, 0, 0, 0, 1}));

  VolumeHeader header;
  header.format = ImageFormat::kMetaImage;
  header.scalar_type = type;
  ImageGeometry& g = header.geometry;
  g.dims = dims;
  for (int axis = 0; axis < 3; ++axis) {
    g.spacing[axis] = spacing[axis];
    g.origin[axis] = origin[axis];
    for (int row = 0; row < 3; ++row) g.direction[3 * row + axis] = matrix[3 * axis + row];
  }
  LABELMESH_RETURN_IF_ERROR(check_spacing(path, "ElementSpacing", g.spacing));
  LABELMESH_RETURN_IF_ERROR(normalise_direction(path, "TransformMatrix", g.direction));

  LABELMESH_ASSIGN_OR_RETURN(auto msb, h.find("BinaryDataByteOrderMSB")
                                           ? optional_bool(path, h, "BinaryDataByteOrderMSB", false)
                                           : optional_bool(path, h, "ElementByteOrderMSB", false));
  header.big_endian = msb;
  auto compressed = optional_bool(path, h, "CompressedData", false);
  if (!compressed.ok()) return compressed.status();

  const std::string_view data_file = *h.find("ElementDataFile");
  if (data_file == "LOCAL") {
    header.data_path = path;
    header.file_offset = h.size;
  } else {
    if (!limits.allow_data_file) {
      return field_error(path, "ElementDataFile", kNoDataFileHere);
    }
    if (data_file.substr(0, 4) == "LIST" || contains(data_file, "%")) {
      return field_error(path, "ElementDataFile", "lists of slice files are not supported");
    }
    if (!is_plain_file_name(data_file)) {
      return field_error(path, "ElementDataFile", "must name a file in the header's own directory");
    }
    header.data_path = sibling_path(path, data_file);
    header.file_offset = 0;
  }
  if (auto skip = h.find("HeaderSize"); skip && *skip != "0") {
    return field_error(path, "HeaderSize", "skipping bytes before the voxels is not supported");
  }

  const uint64_t needed = header.data_bytes();
  auto data_size = file_size(header.data_path);
  if (!data_size.ok()) {
    return field_error(path, "ElementDataFile", "the data file does not exist");
  }
  if (!*compressed) {
    header.encoding = DataEncoding::kRaw;
    LABELMESH_RETURN_IF_ERROR(check_raw_payload(header.data_path, header.file_offset, needed));
    return header;
  }
  header.encoding = DataEncoding::kZlib;
  if (*data_size < header.file_offset) return field_error(path, "voxel data", "is missing");
  header.compressed_bytes = *data_size - header.file_offset;
  if (auto size_text = h.find("CompressedDataSize")) {
    LABELMESH_ASSIGN_OR_RETURN(auto declared,
                               parse_numbers(path, "CompressedDataSize", *size_text, 1));
    const double value = declared[0];
    if (value < 1 || value != std::floor(value) || value > double(header.compressed_bytes)) {
      return field_error(path, "CompressedDataSize",
                         cat("is ", show(value), " but the file holds ", header.compressed_bytes,
                             " bytes of compressed data"));
    }
    // Only a bound check: real files understate it (frogtissue.mhd says 260020
    // of its 262087 bytes), and the zlib stream marks its own end.
  }
  if (auto s = check_encoded_payload(header.data_path, header.file_offset, DataEncoding::kZlib,
                                     header.compressed_bytes, needed);
      !s.ok()) {
    return s;
  }
  return header;
}

}  // namespace labelmesh::volume::internal
