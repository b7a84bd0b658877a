// SPDX-License-Identifier: AGPL-3.0-or-later
// VTK XML image data (.vti) header checks: the <ImageData> element's extent,
// origin, spacing and direction, and the type of the first point-data array.
// Array payloads (inline, appended, compressed) are then decoded by VTK's XML
// reader, which reports short or corrupt data as errors. VTI has no
// anatomical frame; its world coordinates are taken as LPS, as stored.
#include <cmath>
#include <optional>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

// The element starting at `tag` ("<ImageData") up to its closing '>'.
std::optional<std::string_view> find_element(std::string_view xml, std::string_view tag,
                                             size_t from = 0) {
  const size_t start = xml.find(tag, from);
  if (start == std::string_view::npos) return std::nullopt;
  const size_t end = xml.find('>', start);
  if (end == std::string_view::npos) return std::nullopt;
  return xml.substr(start, end - start);
}

// The value of attribute `name` in an element, without the quotes.
std::optional<std::string_view> find_attribute(std::string_view element, std::string_view name) {
  const std::string key = cat(" ", name, "=\"");
  const size_t start = element.find(key);
  if (start == std::string_view::npos) return std::nullopt;
  const size_t value_start = start + key.size();
  const size_t end = element.find('"', value_start);
  if (end == std::string_view::npos) return std::nullopt;
  return element.substr(value_start, end - value_start);
}

absl::StatusOr<ScalarType> vti_scalar_type(const std::string& path, std::string_view name) {
  struct Known {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Known kKnown[] = {
      {"Int8", ScalarType::kInt8},       {"UInt8", ScalarType::kUInt8},
      {"Int16", ScalarType::kInt16},     {"UInt16", ScalarType::kUInt16},
      {"Int32", ScalarType::kInt32},     {"UInt32", ScalarType::kUInt32},
      {"Int64", ScalarType::kInt64},     {"UInt64", ScalarType::kUInt64},
      {"Float32", ScalarType::kFloat32}, {"Float64", ScalarType::kFloat64}};
  for (const auto& known : kKnown) {
    if (known.name == name) return known.type;
  }
  return field_error(path, "DataArray type", "is not an integer or real scalar type");
}

}  // namespace

absl::StatusOr<VolumeHeader> check_vti_header(const std::string& path, const ReadLimits& limits) {
  LABELMESH_ASSIGN_OR_RETURN(auto bytes, read_prefix(path, limits.max_header_bytes, false));
  const std::string_view xml = bytes;
  auto file = find_element(xml, "<VTKFile");
  if (!file || find_attribute(*file, "type") != "ImageData") {
    return field_error(path, "VTKFile", "is not a VTK XML ImageData file");
  }
  auto image = find_element(xml, "<ImageData");
  if (!image) return field_error(path, "ImageData", "element is missing");

  auto extent_text = find_attribute(*image, "WholeExtent");
  if (!extent_text) return field_error(path, "WholeExtent", "is missing");
  LABELMESH_ASSIGN_OR_RETURN(auto extent, parse_numbers(path, "WholeExtent", *extent_text, 6));
  std::array<int64_t, 3> dims{};
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = extent[2 * axis], hi = extent[2 * axis + 1];
    if (lo != std::floor(lo) || hi != std::floor(hi) || std::abs(lo) > 1e12 ||
        std::abs(hi) > 1e12) {
      return field_error(path, "WholeExtent", "must hold whole numbers");
    }
    dims[axis] = static_cast<int64_t>(hi - lo) + 1;
  }
  LABELMESH_RETURN_IF_ERROR(check_dims(path, "WholeExtent", dims, limits));

  VolumeHeader header;
  header.format = ImageFormat::kVti;
  header.data_path = path;
  ImageGeometry& g = header.geometry;
  g.dims = dims;
  if (auto text = find_attribute(*image, "Spacing")) {
    LABELMESH_ASSIGN_OR_RETURN(auto values, parse_numbers(path, "Spacing", *text, 3));
    g.spacing = {values[0], values[1], values[2]};
  }
  LABELMESH_RETURN_IF_ERROR(check_spacing(path, "Spacing", g.spacing));
  if (auto text = find_attribute(*image, "Direction")) {
    LABELMESH_ASSIGN_OR_RETURN(auto values, parse_numbers(path, "Direction", *text, 9));
    std::copy(values.begin(), values.end(), g.direction.begin());
    LABELMESH_RETURN_IF_ERROR(normalise_direction(path, "Direction", g.direction));
  }
  std::array<double, 3> vtk_origin{0, 0, 0};
  if (auto text = find_attribute(*image, "Origin")) {
    LABELMESH_ASSIGN_OR_RETURN(auto values, parse_numbers(path, "Origin", *text, 3));
    vtk_origin = {values[0], values[1], values[2]};
  }
  // Our voxel (0,0,0) is VTK's extent minimum.
  g.origin = vtk_origin;
  for (int row = 0; row < 3; ++row) {
    for (int axis = 0; axis < 3; ++axis) {
      g.origin[row] += g.direction[3 * row + axis] * extent[2 * axis] * g.spacing[axis];
    }
  }
  // A far extent start times a large spacing can leave the finite doubles.
  LABELMESH_RETURN_IF_ERROR(check_finite(path, "Origin/WholeExtent/Spacing", g.origin.data(), 3));

  const size_t point_data = xml.find("<PointData");
  if (point_data == std::string_view::npos) {
    return field_error(path, "PointData", "is missing: labels must be point (voxel) data");
  }
  auto array = find_element(xml, "<DataArray", point_data);
  if (!array) return field_error(path, "PointData", "holds no DataArray");
  auto type_name = find_attribute(*array, "type");
  if (!type_name) return field_error(path, "DataArray type", "is missing");
  LABELMESH_ASSIGN_OR_RETURN(auto type, vti_scalar_type(path, *type_name));
  header.scalar_type = type;
  if (auto components = find_attribute(*array, "NumberOfComponents");
      components && *components != "1") {
    return field_error(path, "NumberOfComponents", "must be 1 for a label volume");
  }
  return header;
}

}  // namespace labelmesh::volume::internal
