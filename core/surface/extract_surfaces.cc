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
#include "core/text.h"

namespace labelmesh::surface {
namespace {

// The label's voxels plus one voxel of background all round, in index space.
vtkSmartPointer<vtkImageData> padded_label_box(const volume::LabelVolume& volume,
                                               const volume::LabelStatistics& label) {
  vtkNew<vtkImageConstantPad> pad;
  pad->SetInputData(volume.voxels);
  pad->SetConstant(0);
  pad->SetOutputWholeExtent(
      static_cast<int>(label.min_index[0] - 1), static_cast<int>(label.max_index[0] + 1),
      static_cast<int>(label.min_index[1] - 1), static_cast<int>(label.max_index[1] + 1),
      static_cast<int>(label.min_index[2] - 1), static_cast<int>(label.max_index[2] + 1));
  pad->Update();
  return pad->GetOutput();
}

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

}  // namespace

absl::StatusOr<std::vector<LabelSurface>> extract_surfaces(
    const volume::LabelVolume& volume, const volume::VolumeStatistics& statistics,
    const std::vector<int32_t>& labels, const RunContext& context) {
  std::vector<LabelSurface> surfaces;
  surfaces.reserve(labels.size());
  for (size_t n = 0; n < labels.size(); ++n) {
    if (auto s = context.check_stop(); !s.ok()) return s;
    const volume::LabelStatistics* label = statistics.find(labels[n]);
    if (label == nullptr) {
      return absl::InvalidArgumentError(cat("label ", labels[n], " is not in the volume"));
    }
    vtkNew<vtkDiscreteFlyingEdges3D> contour;
    contour->SetInputData(padded_label_box(volume, *label));
    contour->SetValue(0, label->label);
    contour->ComputeNormalsOff();
    contour->ComputeGradientsOff();
    contour->ComputeScalarsOff();
    contour->Update();

    LabelSurface surface{label->label, to_patient_space(contour->GetOutput(), volume.geometry)};
    // Fix orientation once per surface: the contour's winding is consistent,
    // so a negative enclosed volume means every triangle faces inwards.
    if (signed_volume(surface.mesh) < 0) surface.mesh.flip_orientation();
    surfaces.push_back(std::move(surface));
    context.report("marching_cubes", double(n + 1) / double(labels.size()));
  }
  return surfaces;
}

}  // namespace labelmesh::surface
