// SPDX-License-Identifier: AGPL-3.0-or-later
// The classical way to smooth a label: blur its mask with a Gaussian and
// take the surface where the blur crosses one half. The wider the blur, the
// fewer steps its surface keeps and the more boundary voxel centres it puts
// on the wrong side: the bench reads the trade between the two from it.
#pragma once

#include <vtkFlyingEdges3D.h>
#include <vtkImageConstantPad.h>
#include <vtkImageData.h>
#include <vtkImageGaussianSmooth.h>
#include <vtkImageThreshold.h>
#include <vtkNew.h>

#include <cmath>

#include "core/surface/extract_surfaces.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/triangle_mesh.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh::testing {

// The surface (LPS, outward) where `label`'s mask blurred by a Gaussian of
// `sigma_voxels` standard deviation (along each voxel axis) crosses 0.5.
inline surface::TriangleMesh gaussian_iso_surface(const volume::LabelVolume& volume,
                                                  const volume::LabelStatistics& label,
                                                  double sigma_voxels) {
  // The label's box with room for the blur's tails all round.
  const int margin = static_cast<int>(std::ceil(3 * sigma_voxels)) + 1;
  vtkNew<vtkImageConstantPad> box;
  box->SetInputData(volume.voxels);
  box->SetConstant(0);
  box->SetOutputWholeExtent(
      static_cast<int>(label.min_index[0]) - margin, static_cast<int>(label.max_index[0]) + margin,
      static_cast<int>(label.min_index[1]) - margin, static_cast<int>(label.max_index[1]) + margin,
      static_cast<int>(label.min_index[2]) - margin, static_cast<int>(label.max_index[2]) + margin);
  vtkNew<vtkImageThreshold> mask;
  mask->SetInputConnection(box->GetOutputPort());
  mask->ThresholdBetween(label.label, label.label);
  mask->SetInValue(1);
  mask->SetOutValue(0);
  mask->SetOutputScalarTypeToFloat();
  vtkNew<vtkImageGaussianSmooth> blur;
  blur->SetInputConnection(mask->GetOutputPort());
  blur->SetDimensionality(3);
  blur->SetStandardDeviations(sigma_voxels, sigma_voxels, sigma_voxels);
  blur->SetRadiusFactors(3, 3, 3);
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputConnection(blur->GetOutputPort());
  contour->SetValue(0, 0.5);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->Update();
  surface::TriangleMesh mesh = surface::to_patient_space(contour->GetOutput(), volume.geometry);
  if (surface::signed_volume(mesh) < 0) mesh.flip_orientation();
  return mesh;
}

}  // namespace labelmesh::testing
