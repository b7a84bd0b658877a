// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/write_surface.h"

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include "core/util/text.h"
#include "core/util/vtk_error_flag.h"

namespace labelmesh::surface {
namespace {

template <typename Writer>
absl::Status run_writer(Writer* writer, vtkPolyData* polydata, const std::string& path) {
  writer->SetInputData(polydata);
  writer->SetFileName(path.c_str());
  vtkNew<VtkErrorFlag> flag;
  writer->AddObserver(vtkCommand::ErrorEvent, flag);
  const int written = writer->Write();
  if (written != 1 || flag->raised) {
    return absl::InternalError(cat(path, ": could not write the surface"));
  }
  return absl::OkStatus();
}

}  // namespace

vtkSmartPointer<vtkPolyData> to_polydata(const TriangleMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    points->SetPoint(static_cast<vtkIdType>(i), mesh.points[i].data());
  }
  vtkNew<vtkCellArray> triangles;
  triangles->AllocateExact(static_cast<vtkIdType>(mesh.triangles.size()),
                           static_cast<vtkIdType>(3 * mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    triangles->InsertNextCell(3, ids);
  }
  auto polydata = vtkSmartPointer<vtkPolyData>::New();
  polydata->SetPoints(points);
  polydata->SetPolys(triangles);
  return polydata;
}

absl::Status write_surface(const TriangleMesh& mesh, const std::string& path,
                           SurfaceFormat format) {
  if (format == SurfaceFormat::kOff) return write_off(mesh, path);
  const auto polydata = to_polydata(mesh);
  switch (format) {
    case SurfaceFormat::kStl: {
      vtkNew<vtkSTLWriter> writer;
      writer->SetFileTypeToBinary();
      return run_writer(writer.Get(), polydata, path);
    }
    case SurfaceFormat::kPly: {
      vtkNew<vtkPLYWriter> writer;
      writer->SetFileTypeToBinary();
      return run_writer(writer.Get(), polydata, path);
    }
    case SurfaceFormat::kObj: {
      vtkNew<vtkOBJWriter> writer;
      return run_writer(writer.Get(), polydata, path);
    }
    case SurfaceFormat::kVtp: {
      vtkNew<vtkXMLPolyDataWriter> writer;
      writer->SetDataModeToAppended();
      writer->SetCompressorTypeToZLib();
      return run_writer(writer.Get(), polydata, path);
    }
    case SurfaceFormat::kOff:
      break;
  }
  return absl::InternalError("unhandled surface format");
}

}  // namespace labelmesh::surface
