// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/mesh_file_parts.h"

#include <algorithm>
#include <charconv>

#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "core/util/text.h"
#include "core/volume/vtk_error_flag.h"

namespace labelmesh::volume_mesh {

std::vector<int32_t> distinct_labels(const std::vector<int32_t>& labels) {
  std::vector<int32_t> distinct = labels;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  return distinct;
}

absl::Status check_positive_labels(const std::vector<int32_t>& labels, const std::string& path,
                                   std::string_view format) {
  for (int32_t label : labels) {
    if (label <= 0) {
      return absl::InvalidArgumentError(
          cat(path, ": label ", label, " is not positive; ", format, " needs labels above 0"));
    }
  }
  return absl::OkStatus();
}

std::string upper_case(std::string text) {
  for (char& c : text)
    if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
  return text;
}

void add_label_fields(const std::vector<int32_t>& labels, const VolumeFileInfo& info,
                      vtkFieldData* fields) {
  for (int32_t label : distinct_labels(labels)) {
    vtkNew<vtkIntArray> array;
    array->SetName(label_group_name(label, info).c_str());
    array->InsertNextValue(label);
    fields->AddArray(array);
  }
  vtkNew<vtkIntArray> space;
  space->SetName(cat("SPACE=", frame_name(info.frame)).c_str());
  space->InsertNextValue(1);
  fields->AddArray(space);
}

absl::Status write_vtu_grid(vtkUnstructuredGrid* grid, const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToZLib();
  vtkNew<VtkErrorFlag> flag;
  writer->AddObserver(vtkCommand::ErrorEvent, flag);
  // The pipeline reports a failed write too; observed, it stays off stderr.
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, flag);
  if (writer->Write() != 1 || flag->raised) {
    return absl::InternalError(cat(path, ": could not write the volume mesh"));
  }
  return absl::OkStatus();
}

void write_msh_head(TextFile& file, const std::vector<int32_t>& labels,
                    const std::vector<std::array<double, 3>>& points, const VolumeFileInfo& info,
                    const std::vector<std::string>& surface_names) {
  const auto groups = distinct_labels(labels);
  file << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  file << "$PhysicalNames\n" << groups.size() + surface_names.size() << '\n';
  for (size_t i = 0; i < surface_names.size(); ++i)
    file << "2 " << i + 1 << " \"" << surface_names[i] << "\"\n";
  for (int32_t label : groups)
    file << "3 " << label << " \"" << label_group_name(label, info) << "\"\n";
  file << "$EndPhysicalNames\n";
  file << "$Nodes\n" << points.size() << '\n';
  for (size_t i = 0; i < points.size(); ++i) {
    const auto p = in_frame(points[i], info.frame);
    file << i + 1 << ' ' << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  }
  file << "$EndNodes\n";
}

void write_medit_head(TextFile& file, const std::vector<int32_t>& labels,
                      const std::vector<std::array<double, 3>>& points,
                      const VolumeFileInfo& info) {
  file << "MeshVersionFormatted 2\n\nDimension 3\n\n";
  file << "# labelmesh: coordinates in mm, SPACE=" << frame_name(info.frame) << '\n';
  for (int32_t label : distinct_labels(labels))
    file << "# ref " << label << ": " << label_group_name(label, info) << '\n';
  file << "Vertices\n" << points.size() << '\n';
  for (const auto& lps : points) {
    const auto p = in_frame(lps, info.frame);
    file << p[0] << ' ' << p[1] << ' ' << p[2] << " 0\n";
  }
}

namespace {

// A coordinate in at most 20 characters, the widest field CalculiX reads:
// the shortest exact form where it fits, else 13 significant digits (a
// ten-thousandth of a nanometre at half a metre). A coordinate a rounding
// from zero, such as -1.1314057027034252e-05, would otherwise take 23.
void write_abaqus_real(TextFile& file, double value) {
  constexpr size_t kWidest = 20;
  char digits[32];
  auto end = std::to_chars(digits, digits + sizeof digits, value).ptr;
  if (static_cast<size_t>(end - digits) > kWidest)
    end = std::to_chars(digits, digits + sizeof digits, value, std::chars_format::general, 13).ptr;
  file << std::string_view(digits, static_cast<size_t>(end - digits));
}

}  // namespace

void write_abaqus_head(TextFile& file, std::string_view what,
                       const std::vector<std::array<double, 3>>& points,
                       const VolumeFileInfo& info) {
  file << "** labelmesh " << what << ": coordinates in mm, SPACE=" << frame_name(info.frame)
       << ", one ELSET per label\n";
  file << "*HEADING\nlabelmesh volume mesh\n";
  file << "*NODE\n";
  for (size_t i = 0; i < points.size(); ++i) {
    const auto p = in_frame(points[i], info.frame);
    file << i + 1;
    for (const double coordinate : p) {
      file << ", ";
      write_abaqus_real(file, coordinate);
    }
    file << '\n';
  }
}

void write_id_lines(TextFile& file, const std::vector<size_t>& ids) {
  for (size_t i = 0; i < ids.size(); ++i) {
    file << ids[i] << (i + 1 == ids.size() || i % 16 == 15 ? "\n" : ", ");
  }
}

std::string beside(const std::string& path, std::string_view suffix, std::string_view replacement) {
  const bool has_suffix = path.size() >= suffix.size() &&
                          std::string_view(path).substr(path.size() - suffix.size()) == suffix;
  return (has_suffix ? path.substr(0, path.size() - suffix.size()) : path) +
         std::string(replacement);
}

}  // namespace labelmesh::volume_mesh
