// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/extract_surfaces.h"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkImageConstantPad.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include "core/surface/surface_statistics.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::surface {
namespace {

// The voxels of `image` inside [lo, hi] plus one voxel of background all
// round, in index space (cropping and padding in one filter).
vtkSmartPointer<vtkImageData> padded_box(vtkImageData* image, const std::array<int64_t, 3>& lo,
                                         const std::array<int64_t, 3>& hi) {
  vtkNew<vtkImageConstantPad> pad;
  pad->SetInputData(image);
  pad->SetConstant(0);
  pad->SetOutputWholeExtent(static_cast<int>(lo[0] - 1), static_cast<int>(hi[0] + 1),
                            static_cast<int>(lo[1] - 1), static_cast<int>(hi[1] + 1),
                            static_cast<int>(lo[2] - 1), static_cast<int>(hi[2] + 1));
  pad->Update();
  return pad->GetOutput();
}

// The outward boundary of the voxels of `image` equal to `value` inside [lo, hi].
TriangleMesh contour_value(vtkImageData* image, int32_t value, const std::array<int64_t, 3>& lo,
                           const std::array<int64_t, 3>& hi,
                           const volume::ImageGeometry& geometry) {
  vtkNew<vtkDiscreteFlyingEdges3D> contour;
  contour->SetInputData(padded_box(image, lo, hi));
  contour->SetValue(0, value);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->Update();
  TriangleMesh mesh = to_patient_space(contour->GetOutput(), geometry);
  // The contour's winding is consistent, so a negative enclosed volume means
  // every triangle faces inwards (mirrored grids): flip once per surface.
  if (signed_volume(mesh) < 0) mesh.flip_orientation();
  return mesh;
}

}  // namespace

TriangleMesh to_patient_space(vtkPolyData* contour, const volume::ImageGeometry& geometry) {
  TriangleMesh mesh;
  vtkPoints* points = contour->GetPoints();
  const vtkIdType point_count = points ? points->GetNumberOfPoints() : 0;
  mesh.points.resize(static_cast<size_t>(point_count));
  for (vtkIdType i = 0; i < point_count; ++i) {
    double index[3];
    points->GetPoint(i, index);
    mesh.points[static_cast<size_t>(i)] = geometry.to_physical({index[0], index[1], index[2]});
  }
  vtkCellArray* polys = contour->GetPolys();
  mesh.triangles.reserve(static_cast<size_t>(polys->GetNumberOfCells()));
  vtkIdType size = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(size, ids);) {
    if (size != 3) continue;
    mesh.triangles.push_back({static_cast<uint32_t>(ids[0]), static_cast<uint32_t>(ids[1]),
                              static_cast<uint32_t>(ids[2])});
  }
  return mesh;
}

absl::StatusOr<std::vector<TriangleMesh>> extract_component_surfaces(
    const volume::LabelComponents& components, const std::vector<int32_t>& ids,
    const volume::ImageGeometry& geometry, const RunContext& context) {
  std::vector<TriangleMesh> surfaces;
  surfaces.reserve(ids.size());
  for (int32_t id : ids) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    if (id < 1 || static_cast<size_t>(id) > components.components.size()) {
      return absl::InvalidArgumentError(cat("component ", id, " does not exist"));
    }
    const auto& component = components.components[static_cast<size_t>(id - 1)];
    surfaces.push_back(
        contour_value(components.ids, id, component.min_index, component.max_index, geometry));
  }
  return surfaces;
}

absl::StatusOr<std::vector<LabelSurface>> extract_surfaces(
    const volume::LabelVolume& volume, const volume::VolumeStatistics& statistics,
    const std::vector<int32_t>& labels, const RunContext& context) {
  std::vector<LabelSurface> surfaces;
  surfaces.reserve(labels.size());
  for (size_t n = 0; n < labels.size(); ++n) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    const volume::LabelStatistics* label = statistics.find(labels[n]);
    if (label == nullptr) {
      return absl::InvalidArgumentError(cat("label ", labels[n], " is not in the volume"));
    }
    LabelSurface surface{label->label, contour_value(volume.voxels, label->label, label->min_index,
                                                     label->max_index, volume.geometry)};
    surfaces.push_back(std::move(surface));
    context.report("marching_cubes", double(n + 1) / double(labels.size()));
  }
  return surfaces;
}

}  // namespace labelmesh::surface
