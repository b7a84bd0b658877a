// SPDX-License-Identifier: AGPL-3.0-or-later
// Small label volumes drawn voxel by voxel, for tests of exact counts.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include "core/volume/label_volume.h"

namespace labelmesh::testing {

// A `dims` grid of 1 mm voxels at the origin; voxel (i, j, k) holds label(i, j, k).
inline volume::LabelVolume label_grid(const std::array<int, 3>& dims,
                                      const std::function<uint8_t(int, int, int)>& label) {
  volume::LabelVolume v;
  v.geometry.dims = {dims[0], dims[1], dims[2]};
  auto labels = vtkSmartPointer<vtkUnsignedCharArray>::New();
  labels->SetNumberOfTuples(int64_t{dims[0]} * dims[1] * dims[2]);
  int64_t n = 0;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) labels->SetValue(n++, label(i, j, k));
  v.voxels = vtkSmartPointer<vtkImageData>::New();
  v.voxels->SetDimensions(dims[0], dims[1], dims[2]);
  v.voxels->GetPointData()->SetScalars(labels);
  return v;
}

}  // namespace labelmesh::testing
