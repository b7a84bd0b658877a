// SPDX-License-Identifier: AGPL-3.0-or-later
// The grid and rasteriser every phantom is drawn with.
#pragma once

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// A grid of `dims` voxels whose centre sits at `centre`.
inline ImageGeometry centred_grid(const std::array<int64_t, 3>& dims,
                                  const std::array<double, 3>& spacing,
                                  const std::array<double, 9>& direction,
                                  const std::array<double, 3>& centre) {
  ImageGeometry g;
  g.dims = dims;
  g.spacing = spacing;
  g.direction = direction;
  g.origin = {0, 0, 0};
  const auto middle =
      g.to_physical({(dims[0] - 1) / 2.0, (dims[1] - 1) / 2.0, (dims[2] - 1) / 2.0});
  for (int row = 0; row < 3; ++row) g.origin[row] = centre[row] - middle[row];
  return g;
}

// Labels every voxel by `label_at(LPS point of its centre)`.
template <typename F>
LabelVolume rasterise(const ImageGeometry& geometry, F&& label_at) {
  LabelVolume volume;
  volume.format = ImageFormat::kNifti;
  volume.file_voxel_type = "uint8";
  volume.geometry = geometry;
  auto labels = vtkSmartPointer<vtkUnsignedCharArray>::New();
  labels->SetNumberOfTuples(geometry.voxel_count());
  uint8_t* out = labels->GetPointer(0);
  const auto& d = geometry.dims;
  for (int64_t k = 0; k < d[2]; ++k) {
    for (int64_t j = 0; j < d[1]; ++j) {
      for (int64_t i = 0; i < d[0]; ++i) {
        const auto p = geometry.to_physical({double(i), double(j), double(k)});
        *out++ = static_cast<uint8_t>(label_at(p));
      }
    }
  }
  volume.voxels = vtkSmartPointer<vtkImageData>::New();
  volume.voxels->SetDimensions(static_cast<int>(d[0]), static_cast<int>(d[1]),
                               static_cast<int>(d[2]));
  volume.voxels->GetPointData()->SetScalars(labels);
  return volume;
}

}  // namespace labelmesh::volume
