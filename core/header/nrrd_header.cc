// SPDX-License-Identifier: AGPL-3.0-or-later
// NRRD (.nrrd attached, .nhdr detached) header checks, after the NRRD0004/5
// format definition: "field: value" lines, a blank line before attached data.
// A 4-D file is read only as a 3D Slicer segmentation with layers: its first
// axis is a list of layers, the other three the grid (slicer_segments.h).
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/header/slicer_segments.h"
#include "core/header/text_header.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

absl::StatusOr<ScalarType> nrrd_scalar_type(const std::string& path, std::string_view name) {
  struct Known {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Known kKnown[] = {{"signed char", ScalarType::kInt8},
                                     {"int8", ScalarType::kInt8},
                                     {"int8_t", ScalarType::kInt8},
                                     {"uchar", ScalarType::kUInt8},
                                     {"unsigned char", ScalarType::kUInt8},
                                     {"uint8", ScalarType::kUInt8},
                                     {"uint8_t", ScalarType::kUInt8},
                                     {"short", ScalarType::kInt16},
                                     {"short int", ScalarType::kInt16},
                                     {"signed short", ScalarType::kInt16},
                                     {"signed short int", ScalarType::kInt16},
                                     {"int16", ScalarType::kInt16},
                                     {"int16_t", ScalarType::kInt16},
                                     {"ushort", ScalarType::kUInt16},
                                     {"unsigned short", ScalarType::kUInt16},
                                     {"unsigned short int", ScalarType::kUInt16},
                                     {"uint16", ScalarType::kUInt16},
                                     {"uint16_t", ScalarType::kUInt16},
                                     {"int", ScalarType::kInt32},
                                     {"signed int", ScalarType::kInt32},
                                     {"int32", ScalarType::kInt32},
                                     {"int32_t", ScalarType::kInt32},
                                     {"uint", ScalarType::kUInt32},
                                     {"unsigned int", ScalarType::kUInt32},
                                     {"uint32", ScalarType::kUInt32},
                                     {"uint32_t", ScalarType::kUInt32},
                                     {"longlong", ScalarType::kInt64},
                                     {"long long", ScalarType::kInt64},
                                     {"long long int", ScalarType::kInt64},
                                     {"signed long long", ScalarType::kInt64},
                                     {"signed long long int", ScalarType::kInt64},
                                     {"int64", ScalarType::kInt64},
                                     {"int64_t", ScalarType::kInt64},
                                     {"ulonglong", ScalarType::kUInt64},
                                     {"unsigned long long", ScalarType::kUInt64},
                                     {"unsigned long long int", ScalarType::kUInt64},
                                     {"uint64", ScalarType::kUInt64},
                                     {"uint64_t", ScalarType::kUInt64},
                                     {"float", ScalarType::kFloat32},
                                     {"double", ScalarType::kFloat64}};
  for (const auto& known : kKnown) {
    if (known.name == name) return known.type;
  }
  return field_error(path, "type", "is not an integer or real scalar type");
}

// Sign flips that take a NRRD space to LPS, per coordinate.
absl::StatusOr<std::array<double, 3>> nrrd_space_to_lps(const std::string& path,
                                                        std::string_view space) {
  if (space == "left-posterior-superior" || space == "LPS") return std::array<double, 3>{1, 1, 1};
  if (space == "right-anterior-superior" || space == "RAS") return std::array<double, 3>{-1, -1, 1};
  if (space == "left-anterior-superior" || space == "LAS") return std::array<double, 3>{1, -1, 1};
  // No anatomical frame: taken as LPS, as stored.
  if (space == "scanner-xyz" || space == "3D-right-handed") return std::array<double, 3>{1, 1, 1};
  return field_error(path, "space",
                     "is not a 3-D space labelmesh knows (LPS, RAS, LAS, scanner-xyz, "
                     "3D-right-handed)");
}

// Layers a Slicer segmentation may stack (its list axis).
constexpr int64_t kMostLayers = 256;

struct NrrdAxes {
  int64_t layers = 1;
  std::array<int64_t, 3> dims{};
};

// "sizes": the grid, after the layer count when `layered`. The voxel limit
// counts every layer's voxels, since all are held in memory while read.
absl::StatusOr<NrrdAxes> nrrd_sizes(const std::string& path, const TextHeader& h, bool layered,
                                    const ReadLimits& limits) {
  auto text = h.find("sizes");
  if (!text) return field_error(path, "sizes", "is missing");
  auto sizes = parse_numbers(path, "sizes", *text, layered ? 4 : 3);
  if (!sizes.ok()) return sizes.status();
  NrrdAxes axes;
  if (layered) {
    const double layers = sizes->front();
    if (layers != std::floor(layers) || layers < 1 || layers > kMostLayers) {
      return field_error(path, "sizes",
                         cat("the layer count must be a whole number from 1 to ", kMostLayers));
    }
    axes.layers = static_cast<int64_t>(layers);
    sizes->erase(sizes->begin());
  }
  LABELMESH_ASSIGN_OR_RETURN(auto whole, whole_sizes(path, "sizes", *sizes));
  axes.dims = whole;
  LABELMESH_RETURN_IF_ERROR(check_dims(path, "sizes", axes.dims, limits));
  const auto voxels = static_cast<uint64_t>(axes.dims[0] * axes.dims[1] * axes.dims[2]);
  if (voxels > limits.max_voxels / static_cast<uint64_t>(axes.layers)) {
    return field_error(path, "sizes",
                       cat(axes.layers, " layers of ", voxels, " voxels exceed the limit of ",
                           limits.max_voxels, " voxels"));
  }
  return axes;
}

// Every axis spatial; in a layered file the first is the list of layers.
absl::Status check_kinds(const std::string& path, const TextHeader& h, bool layered) {
  auto kinds = h.find("kinds");
  if (!kinds) {
    if (!layered) return absl::OkStatus();
    return field_error(path, "kinds", "a 4-D file must say its first axis is a list of layers");
  }
  std::vector<std::string_view> axes = split_any(*kinds, " ");
  if (layered) {
    if (axes.empty() || axes.front() != "list") {
      return field_error(path, "kinds", "the first of 4 axes must be a list (of layers)");
    }
    axes.erase(axes.begin());
  }
  for (std::string_view kind : axes) {
    if (kind != "domain" && kind != "space" && kind != "???" && kind != "none") {
      return field_error(path, "kinds", "every grid axis must be a spatial (domain/space) axis");
    }
  }
  return absl::OkStatus();
}

// A per-axis field without the layered file's list axis, which comes first
// and has no direction or spacing ("none", "nan").
std::optional<std::string_view> grid_part(std::string_view text, bool layered) {
  if (!layered) return text;
  text = trim(text);
  const size_t end = text.find_first_of(" \t");
  if (end == std::string_view::npos) return std::nullopt;
  const std::string_view first = text.substr(0, end);
  if (first != "none" && first != "nan" && first != "NaN") return std::nullopt;
  return text.substr(end + 1);
}

}  // namespace

absl::StatusOr<VolumeHeader> check_nrrd_header(const std::string& path, const ReadLimits& limits) {
  LABELMESH_ASSIGN_OR_RETURN(auto bytes, read_prefix(path, limits.max_header_bytes, false));
  if (!std::string_view(bytes).starts_with("NRRD000")) {
    return field_error(path, "magic", "the file does not start with NRRD000X");
  }
  LABELMESH_ASSIGN_OR_RETURN(
      auto text, parse_text_header(
                     path, bytes,
                     {.separator = ": ", .comment = "#", .last_key = "", .key_value_marker = ":="},
                     limits.max_header_bytes));
  const TextHeader& h = text;

  auto dimension = h.find("dimension");
  if (!dimension || (*dimension != "3" && *dimension != "4")) {
    return field_error(path, "dimension", "must be 3 (4 for a 3D Slicer segmentation's layers)");
  }
  const bool layered = *dimension == "4";
  if (auto space_dimension = h.find("space dimension");
      space_dimension && *space_dimension != "3") {
    return field_error(path, "space dimension", "must be 3");
  }
  LABELMESH_ASSIGN_OR_RETURN(auto axes, nrrd_sizes(path, h, layered, limits));
  LABELMESH_ASSIGN_OR_RETURN(auto segments, parse_slicer_segments(path, h.key_values, axes.layers));
  if (layered && segments.empty()) {
    return field_error(path, "dimension",
                       "is 4, which is read only as a 3D Slicer segmentation (Segment<i>_ keys)");
  }
  auto type_name = h.find("type");
  if (!type_name) return field_error(path, "type", "is missing");
  LABELMESH_ASSIGN_OR_RETURN(auto type, nrrd_scalar_type(path, *type_name));
  LABELMESH_RETURN_IF_ERROR(check_kinds(path, h, layered));
  for (std::string_view skip : {"byte skip", "byteskip", "line skip", "lineskip"}) {
    if (auto value = h.find(skip); value && *value != "0") {
      return field_error(path, skip, "skipping data before the voxels is not supported");
    }
  }

  VolumeHeader header;
  header.format = ImageFormat::kNrrd;
  header.scalar_type = type;
  header.layers = axes.layers;
  header.segments = std::move(segments);
  ImageGeometry& g = header.geometry;
  g.dims = axes.dims;

  std::array<double, 3> to_lps{1, 1, 1};
  if (auto space = h.find("space")) {
    LABELMESH_ASSIGN_OR_RETURN(auto flips, nrrd_space_to_lps(path, *space));
    to_lps = flips;
  }
  if (auto all_directions = h.find("space directions")) {
    auto directions = grid_part(*all_directions, layered);
    if (!directions) {
      return field_error(path, "space directions", "the list axis must come first, as none");
    }
    if (contains(*directions, "none")) {
      return field_error(path, "space directions", "every grid axis needs a direction");
    }
    LABELMESH_ASSIGN_OR_RETURN(auto vectors,
                               parse_numbers(path, "space directions", *directions, 9));
    for (int axis = 0; axis < 3; ++axis) {
      double norm2 = 0;
      for (int row = 0; row < 3; ++row) {
        const double v = to_lps[row] * vectors[3 * axis + row];
        g.direction[3 * row + axis] = v;
        norm2 += v * v;
      }
      g.spacing[axis] = std::sqrt(norm2);
    }
    LABELMESH_RETURN_IF_ERROR(check_spacing(path, "space directions", g.spacing));
    LABELMESH_RETURN_IF_ERROR(normalise_direction(path, "space directions", g.direction));
  } else if (auto all_spacings = h.find("spacings")) {
    auto spacings = grid_part(*all_spacings, layered);
    if (!spacings) return field_error(path, "spacings", "the list axis must come first, as nan");
    LABELMESH_ASSIGN_OR_RETURN(auto values, parse_numbers(path, "spacings", *spacings, 3));
    g.spacing = {values[0], values[1], values[2]};
    LABELMESH_RETURN_IF_ERROR(check_spacing(path, "spacings", g.spacing));
  }
  if (auto origin = h.find("space origin")) {
    LABELMESH_ASSIGN_OR_RETURN(auto values, parse_numbers(path, "space origin", *origin, 3));
    for (int row = 0; row < 3; ++row) g.origin[row] = to_lps[row] * values[row];
  }

  auto encoding = h.find("encoding");
  if (!encoding) return field_error(path, "encoding", "is missing");
  if (*encoding == "raw") {
    header.encoding = DataEncoding::kRaw;
  } else if (*encoding == "gzip" || *encoding == "gz") {
    header.encoding = DataEncoding::kGzip;
  } else {
    return field_error(path, "encoding", "only raw and gzip voxel data are supported");
  }
  if (scalar_size(type) > 1) {
    auto endian = h.find("endian");
    if (!endian || (*endian != "little" && *endian != "big")) {
      return field_error(path, "endian", "must be little or big for multi-byte voxels");
    }
    header.big_endian = *endian == "big";
  }

  auto data_file = h.find("data file");
  if (!data_file) data_file = h.find("datafile");
  if (data_file) {
    if (!limits.allow_data_file) return field_error(path, "data file", kNoDataFileHere);
    if (std::string_view(*data_file).starts_with("LIST") || contains(*data_file, " ") ||
        contains(*data_file, "%")) {
      return field_error(path, "data file", "lists of data files are not supported");
    }
    if (!is_plain_file_name(*data_file)) {
      return field_error(path, "data file", "must name a file in the header's own directory");
    }
    header.data_path = sibling_path(path, *data_file);
    header.file_offset = 0;
  } else {
    if (h.size >= bytes.size() && bytes.size() < limits.max_header_bytes) {
      return field_error(path, "data file", "is missing and no voxels follow the header");
    }
    header.data_path = path;
    header.file_offset = h.size;
  }

  const uint64_t needed = header.data_bytes();
  if (header.encoding == DataEncoding::kRaw) {
    LABELMESH_RETURN_IF_ERROR(check_raw_payload(header.data_path, header.file_offset, needed));
    return header;
  }
  if (auto s = check_encoded_payload(header.data_path, header.file_offset, DataEncoding::kGzip, 0,
                                     needed);
      !s.ok()) {
    return s;
  }
  return header;
}

}  // namespace labelmesh::volume::internal
