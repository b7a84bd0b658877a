// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/write_volume_mesh.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <utility>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "core/util/name_slug.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/text_file.h"
#include "core/volume/vtk_error_flag.h"
#include "core/volume_mesh/mesh_file_parts.h"

namespace labelmesh::volume_mesh {
namespace {

std::string name_of(int32_t label, const VolumeFileInfo& info) {
  const auto found = info.label_names.find(label);
  return found == info.label_names.end() ? std::string() : found->second;
}

vtkNew<vtkPoints> vtk_points(const TetMesh& mesh, const VolumeFileInfo& info) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  for (size_t i = 0; i < mesh.points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), in_frame(mesh.points[i], info.frame).data());
  return points;
}

vtkNew<vtkIntArray> int_array(const char* name, size_t size) {
  vtkNew<vtkIntArray> array;
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(size));
  return array;
}

absl::Status write_interfaces_vtu(const TetMesh& mesh, const VolumeFileInfo& info,
                                  const std::string& path) {
  const Interfaces interfaces(*info.interfaces);
  vtkNew<vtkCellArray> cells;
  auto id = int_array("interface", interfaces.faces.size());
  auto inside = int_array("label_inside", interfaces.faces.size());
  auto outside = int_array("label_outside", interfaces.faces.size());
  for (size_t f = 0; f < interfaces.faces.size(); ++f) {
    const auto& face = interfaces.faces[f];
    const vtkIdType ids[3] = {face.points[0], face.points[1], face.points[2]};
    cells->InsertNextCell(3, ids);
    id->SetValue(static_cast<vtkIdType>(f), static_cast<int>(interfaces.index[f] + 1));
    inside->SetValue(static_cast<vtkIdType>(f), face.labels[0]);
    outside->SetValue(static_cast<vtkIdType>(f), face.labels[1]);
  }
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(vtk_points(mesh, info));
  grid->SetCells(VTK_TRIANGLE, cells);
  grid->GetCellData()->AddArray(id);
  grid->GetCellData()->AddArray(inside);
  grid->GetCellData()->AddArray(outside);
  add_label_fields(mesh.labels, info, grid->GetFieldData());
  return write_vtu_grid(grid, path);
}

absl::Status write_vtu(const TetMesh& mesh, const std::vector<double>& quality,
                       const VolumeFileInfo& info, const std::string& path) {
  if (info.interfaces != nullptr) {
    LABELMESH_RETURN_IF_ERROR(write_interfaces_vtu(mesh, info, interfaces_vtu_path(path)));
  }
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(static_cast<vtkIdType>(mesh.tetrahedra.size()),
                       static_cast<vtkIdType>(4 * mesh.tetrahedra.size()));
  for (const auto& t : mesh.tetrahedra) {
    const vtkIdType ids[4] = {t[0], t[1], t[2], t[3]};
    cells->InsertNextCell(4, ids);
  }
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(vtk_points(mesh, info));
  grid->SetCells(VTK_TETRA, cells);
  auto labels = int_array("label", mesh.labels.size());
  for (size_t i = 0; i < mesh.labels.size(); ++i)
    labels->SetValue(static_cast<vtkIdType>(i), mesh.labels[i]);
  grid->GetCellData()->AddArray(labels);
  add_label_fields(mesh.labels, info, grid->GetFieldData());
  if (!quality.empty()) {
    vtkNew<vtkDoubleArray> values;
    values->SetName("quality");
    values->SetNumberOfValues(static_cast<vtkIdType>(quality.size()));
    for (size_t i = 0; i < quality.size(); ++i)
      values->SetValue(static_cast<vtkIdType>(i), quality[i]);
    grid->GetCellData()->AddArray(values);
  }
  return write_vtu_grid(grid, path);
}

// Gmsh MSH 2.2 ASCII (Gmsh reference manual, "Legacy formats: MSH file format version 2").
absl::Status write_msh(const TetMesh& mesh, const std::vector<double>& quality,
                       const VolumeFileInfo& info, const std::string& path) {
  LABELMESH_RETURN_IF_ERROR(check_positive_labels(mesh.labels, path, "MSH"));
  std::optional<Interfaces> interfaces;
  std::vector<std::string> surface_names;
  if (info.interfaces != nullptr) {
    interfaces.emplace(*info.interfaces);
    for (const auto& pair : interfaces->pairs)
      surface_names.push_back(interface_group_name(pair, info));
  }
  TextFile file(path, "the volume mesh");
  write_msh_head(file, mesh.labels, mesh.points, info, surface_names);
  const size_t triangles = interfaces ? interfaces->faces.size() : 0;
  file << "$Elements\n" << mesh.tetrahedra.size() + triangles << '\n';
  for (size_t i = 0; i < mesh.tetrahedra.size(); ++i) {
    const auto& t = mesh.tetrahedra[i];
    const int32_t label = mesh.labels[i];
    // Type 4 is the 4-node tetrahedron; its two tags are the physical and elementary entity.
    file << i + 1 << " 4 2 " << label << ' ' << label;
    for (uint32_t v : t) file << ' ' << v + 1;
    file << '\n';
  }
  // Triangles after the tetrahedra, so element data keeps numbering tetrahedra from 1.
  for (size_t f = 0; f < triangles; ++f) {
    const size_t group = interfaces->index[f] + 1;
    file << mesh.tetrahedra.size() + f + 1 << " 2 2 " << group << ' ' << group;
    for (uint32_t v : interfaces->faces[f].points) file << ' ' << v + 1;
    file << '\n';
  }
  file << "$EndElements\n";
  // Element data must cover every element for meshio, and Q means nothing for the interface
  // triangles: with interfaces, quality is in the VTU only.
  if (!quality.empty() && !interfaces) {
    // One string tag (the name), one real tag (the time), three integer tags (time step,
    // components, entries).
    file << "$ElementData\n1\n\"quality\"\n1\n0\n3\n0\n1\n" << quality.size() << '\n';
    for (size_t i = 0; i < quality.size(); ++i) file << i + 1 << ' ' << quality[i] << '\n';
    file << "$EndElementData\n";
  }
  return file.finish();
}

// Medit .mesh (INRIA, "The Medit mesh file format"), read by Mmg, Medit, meshio and TetGen.
absl::Status write_medit(const TetMesh& mesh, const VolumeFileInfo& info, const std::string& path) {
  TextFile file(path, "the volume mesh");
  write_medit_head(file, mesh.labels, mesh.points, info);
  if (info.interfaces != nullptr) {
    const Interfaces interfaces(*info.interfaces);
    for (size_t i = 0; i < interfaces.pairs.size(); ++i)
      file << "# triangle ref " << i + 1 << ": " << interface_group_name(interfaces.pairs[i], info)
           << '\n';
    file << "\nTriangles\n" << interfaces.faces.size() << '\n';
    for (size_t f = 0; f < interfaces.faces.size(); ++f) {
      for (uint32_t v : interfaces.faces[f].points) file << v + 1 << ' ';
      file << interfaces.index[f] + 1 << '\n';
    }
  } else {
    const auto faces = label_boundary_faces(mesh);
    file << "\nTriangles\n" << faces.size() << '\n';
    for (const auto& face : faces) {
      for (uint32_t v : face.points) file << v + 1 << ' ';
      file << face.label << '\n';
    }
  }
  file << "\nTetrahedra\n" << mesh.tetrahedra.size() << '\n';
  for (size_t i = 0; i < mesh.tetrahedra.size(); ++i) {
    for (uint32_t v : mesh.tetrahedra[i]) file << v + 1 << ' ';
    file << mesh.labels[i] << '\n';
  }
  file << "\nEnd\n";
  return file.finish();
}

// Abaqus/CalculiX input. C3D4 interpolates u = (1-g-h-r)u1 + g u2 + h u3 + r u4 (Abaqus Theory
// Manual, "Triangular, tetrahedral, and wedge elements"; CalculiX shape4tet.f), so its Jacobian
// is det[p2-p1, p3-p1, p4-p1]: positive exactly for VTK ordering, which is written unchanged.
// Faces (Abaqus Analysis User's Manual, "Three-dimensional solid element library"):
// S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1; indexed here by the omitted local node.
absl::Status write_abaqus(const TetMesh& mesh, const VolumeFileInfo& info,
                          const std::string& path) {
  LABELMESH_RETURN_IF_ERROR(check_positive_labels(mesh.labels, path, "INP"));
  static constexpr std::array<int, 4> kFaceByOmittedNode{3, 4, 2, 1};
  const auto labels = distinct_labels(mesh.labels);
  const auto faces = label_boundary_faces(mesh);
  TextFile file(path, "the volume mesh");
  write_abaqus_head(file, "tetrahedral mesh", mesh.points, info);
  for (int32_t label : labels) {
    file << "*ELEMENT, TYPE=C3D4, ELSET=" << upper_case(label_group_name(label, info)) << '\n';
    for (size_t i = 0; i < mesh.tetrahedra.size(); ++i) {
      if (mesh.labels[i] != label) continue;
      const auto& t = mesh.tetrahedra[i];
      file << i + 1 << ", " << t[0] + 1 << ", " << t[1] + 1 << ", " << t[2] + 1 << ", " << t[3] + 1
           << '\n';
    }
  }
  // Faces come sorted by label, so each label's faces form one run.
  for (size_t begin = 0; begin < faces.size();) {
    const int32_t label = faces[begin].label;
    size_t end = begin;
    std::set<size_t> nodes;
    while (end < faces.size() && faces[end].label == label) {
      for (uint32_t point : faces[end].points) nodes.insert(point + size_t{1});
      ++end;
    }
    const std::string group = upper_case(label_group_name(label, info));
    file << "*NSET, NSET=" << group << "_BOUNDARY\n";
    write_id_lines(file, std::vector<size_t>(nodes.begin(), nodes.end()));
    file << "*SURFACE, TYPE=ELEMENT, NAME=" << group << "_SURFACE\n";
    for (size_t i = begin; i < end; ++i)
      file << faces[i].tet + 1 << ", S" << kFaceByOmittedNode[faces[i].across] << '\n';
    begin = end;
  }
  if (info.interfaces != nullptr) {
    const Interfaces interfaces(*info.interfaces);
    for (size_t f = 0; f < interfaces.faces.size(); ++f) {
      const auto& face = interfaces.faces[f];
      if (f == 0 || interfaces.index[f] != interfaces.index[f - 1]) {
        file << "*SURFACE, TYPE=ELEMENT, NAME="
             << upper_case(interface_group_name(face.labels, info)) << '\n';
      }
      file << face.tet + 1 << ", S" << kFaceByOmittedNode[face.across] << '\n';
    }
  }
  return file.finish();
}

// TetGen .node and .ele (TetGen 1.5 manual, §5.2.1 and §5.2.4). TetGen's tetrahedra have the
// same orientation as VTK's, so corners are written unchanged.
absl::Status write_tetgen(const TetMesh& mesh, const VolumeFileInfo& info,
                          const std::string& path) {
  constexpr std::string_view kSuffix = ".node";
  if (path.size() <= kSuffix.size() ||
      std::string_view(path).substr(path.size() - kSuffix.size()) != kSuffix) {
    return absl::InvalidArgumentError(cat(path, ": a TetGen mesh path must end in .node"));
  }
  const std::string ele_path = path.substr(0, path.size() - kSuffix.size()) + ".ele";
  {
    TextFile file(path, "the volume mesh");
    file << "# labelmesh: points in mm, SPACE=" << frame_name(info.frame) << ", numbered from 1\n";
    file << mesh.points.size() << " 3 0 0\n";
    for (size_t i = 0; i < mesh.points.size(); ++i) {
      const auto p = in_frame(mesh.points[i], info.frame);
      file << i + 1 << ' ' << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    }
    LABELMESH_RETURN_IF_ERROR(file.finish());
  }
  TextFile file(ele_path, "the volume mesh");
  file << "# labelmesh: tetrahedra numbered from 1; the region attribute is the label\n";
  file << mesh.tetrahedra.size() << " 4 1\n";
  for (size_t i = 0; i < mesh.tetrahedra.size(); ++i) {
    file << i + 1;
    for (uint32_t v : mesh.tetrahedra[i]) file << ' ' << v + 1;
    file << ' ' << mesh.labels[i] << '\n';
  }
  return file.finish();
}

}  // namespace

std::string label_group_name(int32_t label, const VolumeFileInfo& info) {
  std::string group = cat("label_", label);
  std::string slug = name_slug(name_of(label, info));
  std::replace(slug.begin(), slug.end(), '-', '_');
  if (!slug.empty()) group += cat("_", slug);
  return group;
}

std::string interface_group_name(const std::array<int32_t, 2>& labels, const VolumeFileInfo& info) {
  return cat(label_group_name(labels[0], info), "__",
             labels[1] == 0 ? std::string("outside") : label_group_name(labels[1], info));
}

std::string interfaces_vtu_path(const std::string& vtu_path) {
  return beside(vtu_path, ".vtu", "_interfaces.vtu");
}

std::string facets_xdmf_path(const std::string& xdmf_path) {
  return beside(xdmf_path, ".xdmf", "_facets.xdmf");
}

absl::Status write_volume_mesh(const TetMesh& mesh, const std::vector<double>& cell_quality,
                               const std::string& path, VolumeFormat format,
                               const VolumeFileInfo& info) {
  if (auto status = check_tet_mesh(mesh); !status.ok()) {
    return absl::InvalidArgumentError(cat(path, ": ", std::string(status.message())));
  }
  if (!cell_quality.empty() && cell_quality.size() != mesh.tetrahedra.size()) {
    return absl::InvalidArgumentError(cat(path, ": ", cell_quality.size(), " quality values for ",
                                          mesh.tetrahedra.size(), " tetrahedra"));
  }
  switch (format) {
    case VolumeFormat::kVtu:
      return write_vtu(mesh, cell_quality, info, path);
    case VolumeFormat::kMsh:
      return write_msh(mesh, cell_quality, info, path);
    case VolumeFormat::kMedit:
      return write_medit(mesh, info, path);
    case VolumeFormat::kAbaqus:
      return write_abaqus(mesh, info, path);
    case VolumeFormat::kTetgen:
      return write_tetgen(mesh, info, path);
    case VolumeFormat::kXdmf:
      return write_xdmf(mesh, cell_quality, info, path);
  }
  return absl::InternalError("unhandled volume format");
}

}  // namespace labelmesh::volume_mesh
