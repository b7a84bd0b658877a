// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/image_geometry.h"

#include <cmath>

namespace labelmesh::volume {
namespace {

// Row-major 3x3 of direction x diag(spacing): index steps to mm.
std::array<double, 9> index_to_mm(const ImageGeometry& g) {
  std::array<double, 9> m{};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      m[3 * row + col] = g.direction[3 * row + col] * g.spacing[col];
  }
  return m;
}

double determinant(const std::array<double, 9>& m) {
  return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
         m[2] * (m[3] * m[7] - m[4] * m[6]);
}

}  // namespace

std::string_view format_name(ImageFormat format) {
  switch (format) {
    case ImageFormat::kNifti:
      return "nifti";
    case ImageFormat::kMetaImage:
      return "metaimage";
    case ImageFormat::kNrrd:
      return "nrrd";
    case ImageFormat::kInr:
      return "inr";
    case ImageFormat::kVti:
      return "vti";
    case ImageFormat::kDicomSeg:
      return "dicom-seg";
  }
  return "unknown";
}

std::array<double, 3> ImageGeometry::to_physical(const std::array<double, 3>& index) const {
  const auto m = index_to_mm(*this);
  std::array<double, 3> p = origin;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) p[row] += m[3 * row + col] * index[col];
  }
  return p;
}

std::array<double, 3> ImageGeometry::to_index(const std::array<double, 3>& point) const {
  const auto m = index_to_mm(*this);
  const double det = determinant(m);
  // Inverse by cofactors: the matrix is 3x3 and well conditioned by construction.
  const std::array<double, 9> inv = {
      (m[4] * m[8] - m[5] * m[7]) / det, (m[2] * m[7] - m[1] * m[8]) / det,
      (m[1] * m[5] - m[2] * m[4]) / det, (m[5] * m[6] - m[3] * m[8]) / det,
      (m[0] * m[8] - m[2] * m[6]) / det, (m[2] * m[3] - m[0] * m[5]) / det,
      (m[3] * m[7] - m[4] * m[6]) / det, (m[1] * m[6] - m[0] * m[7]) / det,
      (m[0] * m[4] - m[1] * m[3]) / det};
  const std::array<double, 3> d{point[0] - origin[0], point[1] - origin[1], point[2] - origin[2]};
  std::array<double, 3> index{};
  for (int row = 0; row < 3; ++row) {
    index[row] = inv[3 * row] * d[0] + inv[3 * row + 1] * d[1] + inv[3 * row + 2] * d[2];
  }
  return index;
}

double ImageGeometry::voxel_volume() const { return std::abs(determinant(index_to_mm(*this))); }

void ImageGeometry::reverse_axis(int axis) {
  const double steps = static_cast<double>(dims[axis] - 1) * spacing[axis];
  for (int row = 0; row < 3; ++row) {
    origin[row] += direction[3 * row + axis] * steps;
    direction[3 * row + axis] = -direction[3 * row + axis];
  }
}

}  // namespace labelmesh::volume
