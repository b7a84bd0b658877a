// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/dicom_seg_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "core/header/header_checks.h"
#include "core/util/status_macros.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;
using Vec3 = std::array<double, 3>;

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Vec3 minus(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

// What the header says the object is, before its geometry is looked at.
absl::Status check_kind(std::string_view path, const internal::DicomSegHeader& header) {
  if (header.sop_class_uid == kLabelMapSegmentationStorage) {
    return field_error(path, "(0008,0016) SOP Class UID",
                       absl::StrCat(absl::string_view(kLabelMapSegmentationStorage.data(),
                                                      kLabelMapSegmentationStorage.size()),
                                    " is Label Map Segmentation Storage, which this version does "
                                    "not read; send a BINARY or FRACTIONAL SEG, or a label map "
                                    "(NRRD, NIfTI)"));
  }
  if (header.sop_class_uid != kSegmentationStorage) {
    return field_error(path, "(0008,0016) SOP Class UID",
                       "is not Segmentation Storage: not a DICOM SEG");
  }
  if (header.has_plane_position_slide || header.dimension_organization_type == "TILED_FULL" ||
      header.dimension_organization_type == "TILED_SPARSE") {
    return field_error(path, "geometry",
                       "a slide microscopy segmentation (tiles in slide coordinates) has no 3D "
                       "patient-space geometry");
  }
  const bool binary = header.segmentation_type == "BINARY";
  const bool fractional = header.segmentation_type == "FRACTIONAL";
  if (!binary && !fractional) {
    return field_error(path, "(0062,0001) Segmentation Type", "is neither BINARY nor FRACTIONAL");
  }
  if (header.bits_allocated != (binary ? 1 : 8)) {
    return field_error(path, "(0028,0100) Bits Allocated",
                       absl::StrCat("is ", header.bits_allocated, "; a ", header.segmentation_type,
                                    " SEG has ", binary ? 1 : 8));
  }
  if (fractional && header.maximum_fractional_value == 0) {
    return field_error(path, "(0062,000E) Maximum Fractional Value", "is missing or 0");
  }
  if (header.rows == 0 || header.columns == 0) {
    return field_error(path, "(0028,0010) Rows / (0028,0011) Columns", "missing or 0");
  }
  if (header.segments == 0) {
    return field_error(path, "(0062,0002) Segment Sequence", "holds no segment");
  }
  // The standard numbers segments 1, 2, 3, ... in sequence order, which is
  // how DCMTK finds them.
  for (size_t i = 0; i < header.segment_numbers.size(); ++i) {
    if (header.segment_numbers[i] != i + 1) {
      return field_error(path, absl::StrCat("segment item ", i + 1, ": (0062,0004) Segment Number"),
                         absl::StrCat("is ", header.segment_numbers[i],
                                      "; segments are numbered 1, "
                                      "2, 3, ... in order"));
    }
  }
  if (header.frame_segments.size() != header.frames) {
    return field_error(path, "(0062,000B) Referenced Segment Number",
                       "is not given for every frame");
  }
  for (size_t f = 0; f < header.frame_segments.size(); ++f) {
    const auto& numbers = header.segment_numbers;
    if (std::find(numbers.begin(), numbers.end(), header.frame_segments[f]) == numbers.end()) {
      return field_error(path, absl::StrCat("frame ", f + 1, ": Referenced Segment Number"),
                         absl::StrCat("names segment ", header.frame_segments[f],
                                      ", which the Segment Sequence does not hold"));
    }
  }
  return absl::OkStatus();
}

constexpr std::string_view kNoPatientGeometry =
    "missing: the SEG has no 3D patient-space geometry (a projection radiograph or another 2D "
    "image?)";

// The unit row and column directions, checked orthogonal.
absl::StatusOr<std::array<Vec3, 2>> plane_axes(std::string_view path,
                                               const std::array<double, 6>& orientation) {
  std::array<Vec3, 2> axes{Vec3{orientation[0], orientation[1], orientation[2]},
                           Vec3{orientation[3], orientation[4], orientation[5]}};
  for (auto& axis : axes) {
    const double length = std::sqrt(dot(axis, axis));
    if (!std::isfinite(length) || length < 0.5 || length > 1.5) {
      return field_error(path, "(0020,0037) Image Orientation (Patient)",
                         "is not made of two unit vectors");
    }
    for (double& v : axis) v /= length;
  }
  if (std::abs(dot(axes[0], axes[1])) > 1e-3) {
    return field_error(path, "(0020,0037) Image Orientation (Patient)",
                       "row and column directions are not perpendicular");
  }
  return axes;
}

}  // namespace

absl::StatusOr<DicomSegGrid> dicom_seg_grid(std::string_view path,
                                            const internal::DicomSegHeader& header,
                                            const ReadLimits& limits) {
  LABELMESH_RETURN_IF_ERROR(check_kind(path, header));
  if (!header.orientation) {
    return field_error(path, "(0020,0037) Image Orientation (Patient)", kNoPatientGeometry);
  }
  if (!header.pixel_spacing) return field_error(path, "(0028,0030) Pixel Spacing", "is missing");
  if (header.frame_positions.size() != header.frames) {
    return field_error(path, "(0020,0032) Image Position (Patient)", kNoPatientGeometry);
  }
  std::vector<Vec3> positions;
  for (size_t f = 0; f < header.frames; ++f) {
    if (!header.frame_positions[f]) {
      return field_error(path, absl::StrCat("frame ", f + 1, ": (0020,0032) Image Position"),
                         kNoPatientGeometry);
    }
    positions.push_back(*header.frame_positions[f]);
    if (auto s =
            internal::check_finite(path, "(0020,0032) Image Position", positions.back().data(), 3);
        !s.ok())
      return s;
  }
  LABELMESH_ASSIGN_OR_RETURN(auto axes, plane_axes(path, *header.orientation));
  const auto& [row_dir, column_dir] = axes;
  const Vec3 normal = cross(row_dir, column_dir);
  const double column_spacing = (*header.pixel_spacing)[1];  // between columns, along a row
  const double row_spacing = (*header.pixel_spacing)[0];
  LABELMESH_RETURN_IF_ERROR(internal::check_spacing(path, "(0028,0030) Pixel Spacing",
                                                    {column_spacing, row_spacing, 1.0}));

  // Every frame must share the first one's in-plane origin.
  const double in_plane_tolerance = 0.01 * std::min(column_spacing, row_spacing);
  std::vector<double> depth(positions.size());
  for (size_t f = 0; f < positions.size(); ++f) {
    const Vec3 offset = minus(positions[f], positions[0]);
    if (std::abs(dot(offset, row_dir)) > in_plane_tolerance ||
        std::abs(dot(offset, column_dir)) > in_plane_tolerance) {
      return field_error(path, absl::StrCat("frame ", f + 1, ": (0020,0032) Image Position"),
                         "is shifted within the plane against frame 1: the frames are not one "
                         "stack of slices");
    }
    depth[f] = dot(offset, normal);
  }
  std::vector<double> sorted = depth;
  std::sort(sorted.begin(), sorted.end());
  const double lowest = sorted.front(), highest = sorted.back();

  double spacing = 0;
  if (header.spacing_between_slices && *header.spacing_between_slices > 0) {
    spacing = *header.spacing_between_slices;
  } else {
    // The smallest gap between distinct slices.
    for (size_t i = 1; i < sorted.size(); ++i) {
      const double gap = sorted[i] - sorted[i - 1];
      if (gap > 1e-4 && (spacing == 0 || gap < spacing)) spacing = gap;
    }
    if (spacing == 0 && header.slice_thickness && *header.slice_thickness > 0)
      spacing = *header.slice_thickness;
  }
  if (!(spacing > 0) || !std::isfinite(spacing)) {
    return field_error(path, "(0018,0088) Spacing Between Slices",
                       "is missing, and one slice without a Slice Thickness gives no spacing");
  }
  const double extent = (highest - lowest) / spacing;
  if (!(extent < double(limits.max_voxels))) {
    return field_error(path, "slice positions",
                       absl::StrCat("span ", highest - lowest, " mm at ", spacing,
                                    " mm spacing: more slices than the voxel limit allows"));
  }
  DicomSegGrid grid;
  grid.frame_slice.resize(positions.size());
  for (size_t f = 0; f < positions.size(); ++f) {
    const double k = (depth[f] - lowest) / spacing;
    if (std::abs(k - std::round(k)) > 0.01) {
      return field_error(path, absl::StrCat("frame ", f + 1, ": (0020,0032) Image Position"),
                         absl::StrCat("lies between slices of the ", spacing, " mm grid"));
    }
    grid.frame_slice[f] = static_cast<int64_t>(std::llround(k));
  }
  ImageGeometry& g = grid.geometry;
  g.dims = {header.columns, header.rows, static_cast<int64_t>(std::llround(extent)) + 1};
  LABELMESH_RETURN_IF_ERROR(internal::check_dims(path, "grid", g.dims, limits));
  g.spacing = {column_spacing, row_spacing, spacing};
  for (int axis = 0; axis < 3; ++axis) g.origin[axis] = positions[0][axis] + normal[axis] * lowest;
  for (int row = 0; row < 3; ++row) {
    g.direction[3 * row + 0] = row_dir[row];
    g.direction[3 * row + 1] = column_dir[row];
    g.direction[3 * row + 2] = normal[row];
  }
  return grid;
}

}  // namespace labelmesh::volume

namespace labelmesh::volume::internal {

absl::StatusOr<VolumeHeader> check_dicom_seg_volume_header(const std::string& path,
                                                           const ReadLimits& limits) {
  LABELMESH_ASSIGN_OR_RETURN(auto header, parse_dicom_seg_header(path));
  LABELMESH_ASSIGN_OR_RETURN(auto grid, dicom_seg_grid(path, header, limits));
  // BINARY frames are one bit a pixel, packed without padding between frames.
  const uint64_t pixels = uint64_t(header.rows) * header.columns * header.frames;
  const uint64_t needed = header.bits_allocated == 1 ? (pixels + 7) / 8 : pixels;
  if (header.pixel_data_bytes < needed) {
    return field_error(
        path, "(7FE0,0010) Pixel Data",
        absl::StrCat("holds ", header.pixel_data_bytes, " bytes; ", header.frames, " frames of ",
                     header.rows, " x ", header.columns, " need ", needed));
  }
  VolumeHeader volume;
  volume.format = ImageFormat::kDicomSeg;
  // Labels are segment numbers, up to 65,535.
  volume.scalar_type = ScalarType::kUInt16;
  volume.geometry = grid.geometry;
  volume.data_path = path;
  volume.file_offset = header.pixel_data_offset;
  return volume;
}

}  // namespace labelmesh::volume::internal
