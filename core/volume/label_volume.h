// SPDX-License-Identifier: AGPL-3.0-or-later
// A label volume in memory: voxels plus where they sit in patient space.
#pragma once

#include <string>
#include <vector>

#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include "core/header/image_geometry.h"
#include "core/header/label_description.h"

namespace labelmesh::volume {

struct LabelVolume {
  ImageFormat format = ImageFormat::kNifti;
  // Voxel type as stored in the file (uint8, int16, float32, ...).
  std::string file_voxel_type;
  ImageGeometry geometry;
  // One integer scalar component per voxel, extent [0, dims-1], spacing 1 and
  // origin 0: index space. `geometry` carries the physical placement.
  vtkSmartPointer<vtkImageData> voxels;
  // What the file says of its labels (DICOM SEG segments); may be empty.
  LabelDescriptions descriptions;
  // Overlapping segments kept apart (ReadLimits::separate_overlapping):
  // further images like `voxels` (same grid and scalar type), each holding
  // segments that overlap something in the images before it. Every label is
  // in exactly one image. Empty for other inputs and when nothing overlaps.
  std::vector<vtkSmartPointer<vtkImageData>> more_layers;
};

}  // namespace labelmesh::volume
