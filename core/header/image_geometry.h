// SPDX-License-Identifier: AGPL-3.0-or-later
// Where a volume's voxels sit in patient space, and its file format.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace labelmesh::volume {

enum class ImageFormat { kNifti, kMetaImage, kNrrd, kInr, kVti, kDicomSeg };

std::string_view format_name(ImageFormat format);

// Maps voxel indices to patient coordinates in millimetres, LPS convention
// (x to the patient's left, y posterior, z superior), the DICOM/ITK frame.
struct ImageGeometry {
  std::array<int64_t, 3> dims{0, 0, 0};
  // mm between voxel centres along each voxel axis.
  std::array<double, 3> spacing{1, 1, 1};
  // LPS position of the centre of voxel (0,0,0), mm.
  std::array<double, 3> origin{0, 0, 0};
  // Row-major 3x3; column c is the unit LPS direction of voxel axis c.
  std::array<double, 9> direction{1, 0, 0, 0, 1, 0, 0, 0, 1};

  // LPS position (mm) of a continuous voxel index.
  std::array<double, 3> to_physical(const std::array<double, 3>& index) const;
  // Continuous voxel index of an LPS position; the inverse of to_physical.
  std::array<double, 3> to_index(const std::array<double, 3>& point) const;
  // Volume of one voxel in mm^3 (|det| of direction x diag(spacing)).
  double voxel_volume() const;
  int64_t voxel_count() const { return dims[0] * dims[1] * dims[2]; }

  // Makes index k run the other way along `axis`: used when a reader stores
  // the voxels in reverse order along an axis.
  void reverse_axis(int axis);
};

}  // namespace labelmesh::volume
