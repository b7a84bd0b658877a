// SPDX-License-Identifier: AGPL-3.0-or-later
// Typed access to the voxels of a LabelVolume without repeating a type switch
// in every algorithm. Label volumes in memory hold int8, uint8, int16, uint16
// or int32 voxels (read_label_volume converts everything else to int32).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkType.h>

namespace labelmesh::volume {

// Calls f(const T* voxels, size_t count) with T the voxel type. Returns false
// when the image holds a type labelmesh does not keep in memory.
template <typename F>
bool visit_voxels(vtkImageData* image, F&& f) {
  vtkDataArray* array = image->GetPointData()->GetScalars();
  if (array == nullptr) return false;
  const auto count = static_cast<size_t>(array->GetNumberOfTuples());
  void* data = array->GetVoidPointer(0);
  switch (array->GetDataType()) {
    case VTK_SIGNED_CHAR:
    case VTK_CHAR:
      std::forward<F>(f)(static_cast<const int8_t*>(data), count);
      return true;
    case VTK_UNSIGNED_CHAR:
      std::forward<F>(f)(static_cast<const uint8_t*>(data), count);
      return true;
    case VTK_SHORT:
      std::forward<F>(f)(static_cast<const int16_t*>(data), count);
      return true;
    case VTK_UNSIGNED_SHORT:
      std::forward<F>(f)(static_cast<const uint16_t*>(data), count);
      return true;
    case VTK_INT:
      std::forward<F>(f)(static_cast<const int32_t*>(data), count);
      return true;
    default:
      return false;
  }
}

}  // namespace labelmesh::volume
