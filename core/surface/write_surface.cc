// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/write_surface.h"

#include <algorithm>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>
#include <vtkStringArray.h>
#include <vtkXMLMultiBlockDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include "core/util/text.h"
#include "core/volume/vtk_error_flag.h"

namespace labelmesh::surface {
namespace {

// zlib's fastest level for surfaces in VTK XML files: on the brain's 40
// surfaces the files are 2 % larger and take 40 % less time to write.
constexpr int kSurfaceZlibLevel = 1;

template <typename Writer>
absl::Status run_writer(Writer* writer, vtkDataObject* data, const std::string& path) {
  writer->SetInputData(data);
  writer->SetFileName(path.c_str());
  vtkNew<VtkErrorFlag> flag;
  writer->AddObserver(vtkCommand::ErrorEvent, flag);
  // The pipeline reports a failed write too; observed, it stays off stderr.
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, flag);
  const int written = writer->Write();
  if (written != 1 || flag->raised) {
    return absl::InternalError(cat(path, ": could not write the surface"));
  }
  return absl::OkStatus();
}

// "label 5 liver", or "label 5" without a name.
std::string label_title(const SurfaceFileInfo& info) {
  return info.name.empty() ? cat("label ", info.label) : cat("label ", info.label, " ", info.name);
}

void add_field_string(vtkFieldData* fields, const char* name, const std::string& value) {
  vtkNew<vtkStringArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fields->AddArray(array);
}

// The label as cell data on every triangle and, with its name and the
// frame, as field data: a reader knows what and where the surface is.
void add_label_arrays(vtkPolyData* polydata, const SurfaceFileInfo& info) {
  vtkNew<vtkIntArray> cell_labels;
  cell_labels->SetName("label");
  cell_labels->SetNumberOfValues(polydata->GetNumberOfCells());
  cell_labels->Fill(info.label);
  polydata->GetCellData()->AddArray(cell_labels);
  vtkNew<vtkIntArray> label;
  label->SetName("label");
  label->InsertNextValue(info.label);
  polydata->GetFieldData()->AddArray(label);
  add_field_string(polydata->GetFieldData(), "name", info.name);
  add_field_string(polydata->GetFieldData(), "SPACE", std::string(frame_name(info.frame)));
}

// Binary STL has an 80-byte header and no other place for words: the frame
// first, where 3D Slicer looks for it, then the label in ASCII.
std::string stl_header(const SurfaceFileInfo& info) {
  std::string header = cat("SPACE=", frame_name(info.frame), " labelmesh label ", info.label);
  std::string ascii;
  for (unsigned char c : info.name) ascii.push_back(c >= 0x20 && c < 0x7f ? char(c) : '_');
  if (!ascii.empty()) header += cat(" ", ascii);
  header.resize(std::min<size_t>(header.size(), 80));
  return header;
}

}  // namespace

vtkSmartPointer<vtkPolyData> to_polydata(const TriangleMesh& mesh, CoordinateFrame frame) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    points->SetPoint(static_cast<vtkIdType>(i), in_frame(mesh.points[i], frame).data());
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

absl::Status write_surface(const TriangleMesh& mesh, const std::string& path, SurfaceFormat format,
                           const SurfaceFileInfo& info) {
  switch (format) {
    case SurfaceFormat::kOff: {
      if (info.frame == CoordinateFrame::kLps) return write_off(mesh, path);
      TriangleMesh moved = mesh;
      for (auto& p : moved.points) p = in_frame(p, info.frame);
      return write_off(moved, path);
    }
    case SurfaceFormat::kObj:
      return write_obj(mesh, path, info);
    case SurfaceFormat::kStl: {
      vtkNew<vtkSTLWriter> writer;
      writer->SetFileTypeToBinary();
      writer->SetHeader(stl_header(info).c_str());
      return run_writer(writer.Get(), to_polydata(mesh, info.frame), path);
    }
    case SurfaceFormat::kPly: {
      vtkNew<vtkPLYWriter> writer;
      writer->SetFileTypeToBinary();
      writer->AddComment(cat("SPACE=", frame_name(info.frame)));
      writer->AddComment(cat("labelmesh ", label_title(info)));
      return run_writer(writer.Get(), to_polydata(mesh, info.frame), path);
    }
    case SurfaceFormat::kVtp: {
      auto polydata = to_polydata(mesh, info.frame);
      add_label_arrays(polydata, info);
      vtkNew<vtkXMLPolyDataWriter> writer;
      writer->SetDataModeToAppended();
      writer->SetCompressorTypeToZLib();
      writer->SetCompressionLevel(kSurfaceZlibLevel);
      return run_writer(writer.Get(), polydata, path);
    }
  }
  return absl::InternalError("unhandled surface format");
}

absl::Status write_surface_scene(const std::vector<const TriangleMesh*>& meshes,
                                 const std::vector<SurfaceFileInfo>& infos,
                                 const std::string& path) {
  if (meshes.size() != infos.size()) {
    return absl::InvalidArgumentError(
        cat(path, ": ", meshes.size(), " surfaces for ", infos.size(), " labels"));
  }
  vtkNew<vtkMultiBlockDataSet> scene;
  scene->SetNumberOfBlocks(static_cast<unsigned>(meshes.size()));
  for (size_t i = 0; i < meshes.size(); ++i) {
    auto polydata = to_polydata(*meshes[i], infos[i].frame);
    add_label_arrays(polydata, infos[i]);
    const auto block = static_cast<unsigned>(i);
    scene->SetBlock(block, polydata);
    scene->GetMetaData(block)->Set(vtkCompositeDataSet::NAME(), label_title(infos[i]).c_str());
  }
  vtkNew<vtkXMLMultiBlockDataWriter> writer;
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToZLib();
  writer->SetCompressionLevel(kSurfaceZlibLevel);
  return run_writer(writer.Get(), scene, path);
}

}  // namespace labelmesh::surface
