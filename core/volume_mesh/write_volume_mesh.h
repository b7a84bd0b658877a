// SPDX-License-Identifier: AGPL-3.0-or-later
// Tetrahedral mesh files for viewers and finite-element solvers: VTK XML unstructured grid,
// Gmsh MSH 2.2, Medit, Abaqus/CalculiX input, TetGen's .node/.ele pair and XDMF.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/job/volume_format.h"
#include "core/util/coordinate_frame.h"
#include "core/volume_mesh/tet_mesh.h"

namespace labelmesh::volume_mesh {

// What a volume mesh file says besides its elements.
struct VolumeFileInfo {
  // Names of labels, where known; a label without one is "label_<N>".
  std::map<int32_t, std::string> label_names;
  // Points are written in this frame; the files that have comments or field data say which.
  CoordinateFrame frame = CoordinateFrame::kLps;
  // A conforming mesh's interfaces, interface_faces(mesh) when set: each face
  // between two labels, or between a label and the outside, written once and
  // grouped by label pair, as described for each format below.
  const std::vector<InterfaceFace>* interfaces = nullptr;
};

// The name of an interface's group: "<label group>__<label group>", or
// "<label group>__outside" on the outer boundary.
std::string interface_group_name(const std::array<int32_t, 2>& labels, const VolumeFileInfo& info);

// Where the VTU writer puts the interfaces: "x_interfaces.vtu" beside "x.vtu".
std::string interfaces_vtu_path(const std::string& vtu_path);

// Where the XDMF writer puts the interfaces: "x_facets.xdmf" beside "x.xdmf".
std::string facets_xdmf_path(const std::string& xdmf_path);

// "label_<N>" or "label_<N>_<slug of the name>": a group name every format accepts.
std::string label_group_name(int32_t label, const VolumeFileInfo& info);

// Writes `mesh` to `path`. Coordinates are written in mm, in full precision, in `info.frame`. Every
// format keeps the mesh's node ordering (VTK's, which Gmsh, Medit, TetGen and C3D4 share), so no
// element is inverted. `cell_quality` is empty or holds one value per tetrahedron; it is written to
// VTU and MSH, the formats with a place for element data.
//
// - kVtu: vtkUnstructuredGrid, appended zlib-compressed data; cell arrays "label" (int32) and
//   "quality" (float64, when given); numeric field data (meshio reads no strings): one array
//   per label present, named by label_group_name and holding the label, and "SPACE=LPS" (or
//   "SPACE=RAS") holding 1.
// - kMsh: Gmsh MSH 2.2 ASCII. One 3D physical group per label, tag = label, named by
//   label_group_name;
//   each tetrahedron (type 4) carries physical and elementary tag = its label. Quality goes to an
//   $ElementData block named "quality". Labels must be positive.
// - kMedit: MeshVersionFormatted 2 (double precision), comments naming the frame and each
//   label. Tetrahedra with ref = label, and the
//   triangles of each label's boundary (see label_boundary_faces) with ref = label, wound out of
//   that label's region; vertices have ref 0.
// - kAbaqus: Abaqus/CalculiX .inp with 1-based ids (element id = tetrahedron index + 1); each
//   coordinate within the 20 characters CalculiX reads (13 significant digits where the
//   shortest exact form is longer). C3D4
//   elements in ELSET=<G>, NSET=<G>_BOUNDARY with the nodes of that label's boundary, and
//   SURFACE NAME=<G>_SURFACE, TYPE=ELEMENT with the element faces on it, where <G> is
//   label_group_name in upper case (LABEL_5_LIVER).
//   Labels must be positive.
// - kTetgen: `path` must end in ".node"; writes it and the .ele beside it, 1-based, with the
//   label as each tetrahedron's region attribute.
// - kXdmf: XDMF 3, data inline as XML text (meshio, ParaView and dolfinx read it): one uniform
//   grid "mesh" of tetrahedra (0-based), XYZ geometry, cell attributes "label" (int32, the
//   cell tags) and "quality" (when given); comments name the frame, the units (mm) and each
//   label's group.
//
// With info.interfaces set, interface i (1-based, in label-pair order) is also written:
// - kVtu: a second file (interfaces_vtu_path) of the same points and the interface triangles,
//   cell arrays "interface" (i), "label_inside" and "label_outside" (the face's normal points
//   from the first into the second; 0 is the outside).
// - kMsh: triangles (type 2) after the tetrahedra, in 2D physical group i named by
//   interface_group_name; no quality block (element data would have to cover the triangles).
// - kMedit: the triangles are the interface faces, once each, with ref = i (comments name them),
//   instead of each label's boundary.
// - kAbaqus: also *SURFACE, TYPE=ELEMENT, NAME=<interface group in upper case> per interface,
//   the faces taken from the first label's elements.
// - kXdmf: a second file (facets_xdmf_path), grid "facets" of the interface triangles on the
//   same points, cell attributes "interface" (i; the facet tags), "label_inside" and
//   "label_outside", and a comment naming each interface.
//
// Errors: INVALID_ARGUMENT naming the file when the mesh is malformed (see check_tet_mesh), the
// quality count is wrong, a label is not positive where it must be, or a TetGen path does not
// end in ".node"; INTERNAL naming the file when it cannot be written.
absl::Status write_volume_mesh(const TetMesh& mesh, const std::vector<double>& cell_quality,
                               const std::string& path, VolumeFormat format,
                               const VolumeFileInfo& info = {});

}  // namespace labelmesh::volume_mesh
