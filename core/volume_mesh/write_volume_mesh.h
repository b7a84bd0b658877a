// SPDX-License-Identifier: AGPL-3.0-or-later
// Tetrahedral mesh files for viewers and finite-element solvers: VTK XML unstructured grid,
// Gmsh MSH 2.2, Medit, Abaqus/CalculiX input, and TetGen's .node/.ele pair.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/volume_mesh/tet_mesh.h"
#include "core/volume_mesh/volume_format.h"

namespace labelmesh::volume_mesh {

// Writes `mesh` to `path`. Coordinates are written in mm, in full precision. Every format keeps
// the mesh's node ordering (VTK's, which Gmsh, Medit, TetGen and C3D4 share), so no element is
// inverted. `cell_quality` is empty or holds one value per tetrahedron; it is written to VTU and
// MSH, the formats with a place for element data.
//
// - kVtu: vtkUnstructuredGrid, appended zlib-compressed data; cell arrays "label" (int32) and
//   "quality" (float64, when given).
// - kMsh: Gmsh MSH 2.2 ASCII. One 3D physical group per label, tag = label, named "label_<N>";
//   each tetrahedron (type 4) carries physical and elementary tag = its label. Quality goes to an
//   $ElementData block named "quality". Labels must be positive.
// - kMedit: MeshVersionFormatted 2 (double precision). Tetrahedra with ref = label, and the
//   triangles of each label's boundary (see label_boundary_faces) with ref = label, wound out of
//   that label's region; vertices have ref 0.
// - kAbaqus: Abaqus/CalculiX .inp with 1-based ids (element id = tetrahedron index + 1). C3D4
//   elements in ELSET=LABEL_<N>, NSET=LABEL_<N>_BOUNDARY with the nodes of that label's
//   boundary, and SURFACE NAME=LABEL_<N>_SURFACE, TYPE=ELEMENT with the element faces on it.
//   Labels must be positive.
// - kTetgen: `path` must end in ".node"; writes it and the .ele beside it, 1-based, with the
//   label as each tetrahedron's region attribute.
//
// Errors: INVALID_ARGUMENT naming the file when the mesh is malformed (see check_tet_mesh), the
// quality count is wrong, a label is not positive where it must be, or a TetGen path does not
// end in ".node"; INTERNAL naming the file when it cannot be written.
absl::Status write_volume_mesh(const TetMesh& mesh, const std::vector<double>& cell_quality,
                               const std::string& path, VolumeFormat format);

}  // namespace labelmesh::volume_mesh
