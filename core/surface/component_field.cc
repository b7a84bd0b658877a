// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/component_field.h"

#include <cmath>

#include <vtkImageData.h>
#include <vtkImageGaussianSmooth.h>
#include <vtkNew.h>

#include "core/util/text.h"

namespace labelmesh::surface {

absl::StatusOr<ScalarGrid> component_field(const volume::LabelComponents& components, int32_t id,
                                           const volume::ImageGeometry& geometry,
                                           double sigma_voxels) {
  if (id < 1 || size_t(id) > components.components.size() || components.ids == nullptr)
    return absl::InvalidArgumentError(cat("component field: no component ", id));
  if (!(sigma_voxels >= 0) || !std::isfinite(sigma_voxels))
    return absl::InvalidArgumentError("component field: sigma must be 0 or more");
  const auto& component = components.components[size_t(id - 1)];
  // Two voxels of background, and three standard deviations for the
  // Gaussian to fade out within the grid.
  const int64_t pad = 2 + static_cast<int64_t>(std::ceil(3 * sigma_voxels));
  std::array<int64_t, 3> low{}, dims{};
  for (int a = 0; a < 3; ++a) {
    low[a] = component.min_index[a] - pad;
    dims[a] = component.max_index[a] - component.min_index[a] + 1 + 2 * pad;
  }
  vtkNew<vtkImageData> mask;
  mask->SetDimensions(static_cast<int>(dims[0]), static_cast<int>(dims[1]),
                      static_cast<int>(dims[2]));
  mask->AllocateScalars(VTK_FLOAT, 1);
  auto* values = static_cast<float*>(mask->GetScalarPointer());
  int extent[6];
  components.ids->GetExtent(extent);
  const auto* ids = static_cast<const int32_t*>(components.ids->GetScalarPointer());
  const int64_t id_nx = extent[1] - extent[0] + 1, id_ny = extent[3] - extent[2] + 1;
  size_t at = 0;
  for (int64_t k = 0; k < dims[2]; ++k) {
    for (int64_t j = 0; j < dims[1]; ++j) {
      for (int64_t i = 0; i < dims[0]; ++i, ++at) {
        // Position in the ids image; outside it is background.
        const int64_t x = low[0] + i - extent[0], y = low[1] + j - extent[2],
                      z = low[2] + k - extent[4];
        const bool in_image =
            x >= 0 && x < id_nx && y >= 0 && y < id_ny && z >= 0 && z <= extent[5] - extent[4];
        values[at] = in_image && ids[x + id_nx * (y + id_ny * z)] == id ? 1.0f : 0.0f;
      }
    }
  }
  ScalarGrid grid;
  grid.dims = dims;
  grid.origin = geometry.to_physical({double(low[0]), double(low[1]), double(low[2])});
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      grid.index_to_mm[size_t(3 * r + c)] =
          geometry.direction[size_t(3 * r + c)] * geometry.spacing[size_t(c)];
  }
  const size_t count = size_t(dims[0] * dims[1] * dims[2]);
  if (sigma_voxels == 0) {
    grid.values.assign(values, values + count);
    return grid;
  }
  vtkNew<vtkImageGaussianSmooth> smooth;
  smooth->SetInputData(mask);
  smooth->SetDimensionality(3);
  smooth->SetStandardDeviations(sigma_voxels, sigma_voxels, sigma_voxels);
  smooth->SetRadiusFactors(3, 3, 3);
  // Labels are meshed in parallel already.
  smooth->SetNumberOfThreads(1);
  smooth->Update();
  const auto* smoothed = static_cast<const float*>(smooth->GetOutput()->GetScalarPointer());
  grid.values.assign(smoothed, smoothed + count);
  return grid;
}

}  // namespace labelmesh::surface
