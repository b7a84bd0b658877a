// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/write_mixed_mesh.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include "core/mixed_mesh/mixed_faces.h"
#include "core/util/coordinate_frame.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/text_file.h"
#include "core/volume/vtk_error_flag.h"
#include "core/volume_mesh/mesh_file_parts.h"

namespace labelmesh::mixed_mesh {
namespace {

using volume_mesh::add_label_fields;
using volume_mesh::check_positive_labels;
using volume_mesh::distinct_labels;
using volume_mesh::label_group_name;
using volume_mesh::upper_case;
using volume_mesh::VolumeFileInfo;
using volume_mesh::VolumeFormat;
using volume_mesh::write_id_lines;
using volume_mesh::write_msh_head;

constexpr std::array<CellType, 4> kTypes{CellType::kHexahedron, CellType::kWedge,
                                         CellType::kPyramid, CellType::kTetra};

int vtk_type(CellType type) {
  switch (type) {
    case CellType::kHexahedron:
      return VTK_HEXAHEDRON;
    case CellType::kWedge:
      return VTK_WEDGE;
    case CellType::kPyramid:
      return VTK_PYRAMID;
    case CellType::kTetra:
      return VTK_TETRA;
  }
  return VTK_EMPTY_CELL;
}

// A cell's nodes in the ordering of Gmsh, Medit and Abaqus. Hexahedra, pyramids and tetrahedra
// keep VTK's. Prisms differ: Gmsh's reference prism has nodes 0,1,2 at (0,0,-1), (1,0,-1),
// (0,1,-1) (reference manual, "Node ordering"), counter-clockwise seen from nodes 3,4,5. Abaqus
// C3D6 and CalculiX (shape6w.f) have face 1-2-3 with nodes 4-6 on its positive side. meshio
// reads Medit's Prisms unchanged into its own wedge ordering, which is Gmsh's (it reorders VTK
// wedges to it, meshio/_vtk_common.py), as is P.-L. George's reference prism (trihedron
// 01, 02, 03 direct; "Génération automatique de maillages", 1994). VTK's wedge winds 0,1,2
// clockwise seen from the top (vtkWedge.h), so both triangles are reversed here. `gmsh -check`
// reports a VTK-ordered prism as negative volume and this one as valid.
std::array<uint32_t, 8> solver_order(CellType type, const std::array<uint32_t, 8>& nodes) {
  if (type != CellType::kWedge) return nodes;
  return {nodes[0], nodes[2], nodes[1], nodes[3], nodes[5], nodes[4], 0, 0};
}

void add_cell_array(vtkUnstructuredGrid* grid, const char* name,
                    const std::vector<double>& values) {
  if (values.empty()) return;
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) array->SetValue(static_cast<vtkIdType>(i), values[i]);
  grid->GetCellData()->AddArray(array);
}

vtkSmartPointer<vtkUnstructuredGrid> make_grid(const MixedMesh& mesh, const VolumeFileInfo& info) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  for (size_t i = 0; i < mesh.points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), in_frame(mesh.points[i], info.frame).data());
  vtkNew<vtkCellArray> cells;
  std::vector<int> types(mesh.size());
  vtkNew<vtkIntArray> labels, element_types;
  labels->SetName("label");
  element_types->SetName("element_type");
  for (size_t c = 0; c < mesh.size(); ++c) {
    const int n = node_count(mesh.types[c]);
    vtkIdType ids[8];
    for (int k = 0; k < n; ++k) ids[k] = mesh.cells[c][k];
    cells->InsertNextCell(n, ids);
    types[c] = vtk_type(mesh.types[c]);
    labels->InsertNextValue(mesh.labels[c]);
    element_types->InsertNextValue(types[c]);
  }
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(points);
  grid->SetCells(types.data(), cells);
  grid->GetCellData()->AddArray(labels);
  grid->GetCellData()->AddArray(element_types);
  add_label_fields(mesh.labels, info, grid->GetFieldData());
  return grid;
}

absl::Status write_vtu(const MixedMesh& mesh, const MixedQuality& quality,
                       const VolumeFileInfo& info, const std::string& path) {
  const auto grid = make_grid(mesh, info);
  add_cell_array(grid, "jacobian_ratio", quality.jacobian_ratio);
  add_cell_array(grid, "quality", quality.quality);
  return volume_mesh::write_vtu_grid(grid, path);
}

// MSH 2.2 element type numbers (Gmsh reference manual, "MSH file format version 2").
int gmsh_type(CellType type) {
  switch (type) {
    case CellType::kHexahedron:
      return 5;
    case CellType::kWedge:
      return 6;
    case CellType::kPyramid:
      return 7;
    case CellType::kTetra:
      return 4;
  }
  return 0;
}

// Gmsh MSH 2.2 ASCII (Gmsh reference manual, "Legacy formats: MSH file format version 2").
// No $ElementData: meshio's MSH 2.2 reader fails on element data over more than one cell type
// (its issue #1257), and FE users read MSH with meshio; the VTU has the qualities.
absl::Status write_msh(const MixedMesh& mesh, const VolumeFileInfo& info, const std::string& path) {
  LABELMESH_RETURN_IF_ERROR(check_positive_labels(mesh.labels, path, "MSH"));
  TextFile file(path, "the volume mesh");
  write_msh_head(file, mesh.labels, mesh.points, info);
  file << "$Elements\n" << mesh.size() << '\n';
  for (size_t c = 0; c < mesh.size(); ++c) {
    const CellType type = mesh.types[c];
    const auto nodes = solver_order(type, mesh.cells[c]);
    // Two tags: the physical and the elementary entity.
    file << c + 1 << ' ' << gmsh_type(type) << " 2 " << mesh.labels[c] << ' ' << mesh.labels[c];
    for (int k = 0; k < node_count(type); ++k) file << ' ' << nodes[k] + 1;
    file << '\n';
  }
  file << "$EndElements\n";
  return file.finish();
}

std::string_view medit_keyword(CellType type) {
  switch (type) {
    case CellType::kHexahedron:
      return "Hexahedra";
    case CellType::kWedge:
      return "Prisms";
    case CellType::kPyramid:
      return "Pyramids";
    case CellType::kTetra:
      return "Tetrahedra";
  }
  return "";
}

void write_medit_faces(TextFile& file, const MixedMesh& mesh, const std::vector<CellFace>& faces,
                       uint8_t size) {
  const auto count = std::count_if(faces.begin(), faces.end(),
                                   [&](const CellFace& face) { return face.size == size; });
  if (count == 0) return;
  file << '\n' << (size == 3 ? "Triangles" : "Quadrilaterals") << '\n' << count << '\n';
  for (const CellFace& face : faces) {
    if (face.size != size) continue;
    for (int k = 0; k < size; ++k) file << face.points[k] + 1 << ' ';
    file << mesh.labels[face.cell] << '\n';
  }
}

// Medit .mesh (INRIA, "The Medit mesh file format"; keywords as meshio's medit reader knows
// them). Sections without entries are left out.
absl::Status write_medit(const MixedMesh& mesh, const VolumeFileInfo& info,
                         const std::string& path) {
  const auto faces = label_boundary_faces(mesh);
  TextFile file(path, "the volume mesh");
  volume_mesh::write_medit_head(file, mesh.labels, mesh.points, info);
  write_medit_faces(file, mesh, faces, 3);
  write_medit_faces(file, mesh, faces, 4);
  for (CellType type : kTypes) {
    const size_t count = mesh.count(type);
    if (count == 0) continue;
    file << '\n' << medit_keyword(type) << '\n' << count << '\n';
    for (size_t c = 0; c < mesh.size(); ++c) {
      if (mesh.types[c] != type) continue;
      const auto nodes = solver_order(type, mesh.cells[c]);
      for (int k = 0; k < node_count(type); ++k) file << nodes[k] + 1 << ' ';
      file << mesh.labels[c] << '\n';
    }
  }
  file << "\nEnd\n";
  return file.finish();
}

// Writes ids as Abaqus data lines of at most 16 entries.
void write_abaqus_elements(TextFile& file, const MixedMesh& mesh, CellType type) {
  if (mesh.count(type) == 0) return;
  static constexpr std::array<int, 8> kCollapsedPyramid{0, 1, 2, 3, 4, 4, 4, 4};
  switch (type) {
    case CellType::kHexahedron:
      file << "*ELEMENT, TYPE=C3D8\n";
      break;
    case CellType::kWedge:
      file << "*ELEMENT, TYPE=C3D6\n";
      break;
    case CellType::kPyramid:
      file << "** pyramids: C3D8 with the apex repeated, nodes 1, 2, 3, 4, 5, 5, 5, 5\n"
              "*ELEMENT, TYPE=C3D8\n";
      break;
    case CellType::kTetra:
      file << "*ELEMENT, TYPE=C3D4\n";
      break;
  }
  for (size_t c = 0; c < mesh.size(); ++c) {
    if (mesh.types[c] != type) continue;
    const auto nodes = solver_order(type, mesh.cells[c]);
    file << c + 1;
    if (type == CellType::kPyramid) {
      for (int k : kCollapsedPyramid) file << ", " << nodes[k] + 1;
    } else {
      for (int k = 0; k < node_count(type); ++k) file << ", " << nodes[k] + 1;
    }
    file << '\n';
  }
}

// Abaqus/CalculiX input. C3D8 shares VTK's hexahedron ordering (CalculiX shape8h.f: nodes 1-4 at
// ζ = -1 counter-clockwise seen from nodes 5-8), C3D4 VTK's tetrahedron (shape4tet.f); C3D6 is
// the reordered wedge of solver_order (shape6w.f). Each label's set is one *ELSET listing ids
// rather than ELSET= on each *ELEMENT block: Abaqus would unite same-named sets across blocks,
// but meshio keeps only the last block's.
absl::Status write_abaqus(const MixedMesh& mesh, const VolumeFileInfo& info,
                          const std::string& path) {
  LABELMESH_RETURN_IF_ERROR(check_positive_labels(mesh.labels, path, "INP"));
  const auto faces = label_boundary_faces(mesh);
  TextFile file(path, "the volume mesh");
  volume_mesh::write_abaqus_head(file, "mixed-element mesh", mesh.points, info);
  for (CellType type : kTypes) write_abaqus_elements(file, mesh, type);
  for (int32_t label : distinct_labels(mesh.labels)) {
    const std::string group = upper_case(label_group_name(label, info));
    std::vector<size_t> elements;
    for (size_t c = 0; c < mesh.size(); ++c)
      if (mesh.labels[c] == label) elements.push_back(c + 1);
    file << "*ELSET, ELSET=" << group << '\n';
    write_id_lines(file, elements);
    std::set<size_t> nodes;
    for (const CellFace& face : faces) {
      if (mesh.labels[face.cell] != label) continue;
      for (int k = 0; k < face.size; ++k) nodes.insert(face.points[k] + size_t{1});
    }
    if (nodes.empty()) continue;
    file << "*NSET, NSET=" << group << "_BOUNDARY\n";
    write_id_lines(file, std::vector<size_t>(nodes.begin(), nodes.end()));
  }
  return file.finish();
}

absl::Status check_quality_size(const MixedMesh& mesh, const std::vector<double>& values,
                                std::string_view name, const std::string& path) {
  if (values.empty() || values.size() == mesh.size()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      cat(path, ": ", values.size(), " ", name, " values for ", mesh.size(), " cells"));
}

}  // namespace

absl::Status write_mixed_mesh(const MixedMesh& mesh, const MixedQuality& quality,
                              const std::string& path, VolumeFormat format,
                              const VolumeFileInfo& info) {
  if (auto status = check_mixed_mesh(mesh); !status.ok()) {
    return absl::InvalidArgumentError(cat(path, ": ", std::string(status.message())));
  }
  LABELMESH_RETURN_IF_ERROR(
      check_quality_size(mesh, quality.jacobian_ratio, "jacobian_ratio", path));
  LABELMESH_RETURN_IF_ERROR(check_quality_size(mesh, quality.quality, "quality", path));
  switch (format) {
    case VolumeFormat::kVtu:
      return write_vtu(mesh, quality, info, path);
    case VolumeFormat::kMsh:
      return write_msh(mesh, info, path);
    case VolumeFormat::kMedit:
      return write_medit(mesh, info, path);
    case VolumeFormat::kAbaqus:
      return write_abaqus(mesh, info, path);
    case VolumeFormat::kTetgen:
      return absl::InvalidArgumentError(
          cat(path, ": TetGen's .node/.ele holds tetrahedra only, not a mixed-element mesh"));
    case VolumeFormat::kXdmf:
      return absl::InvalidArgumentError(
          cat(path,
              ": labelmesh writes XDMF for tetrahedral meshes only, not a mixed-element "
              "mesh"));
  }
  return absl::InternalError("unhandled volume format");
}

}  // namespace labelmesh::mixed_mesh
