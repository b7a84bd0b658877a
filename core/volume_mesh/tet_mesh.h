// SPDX-License-Identifier: AGPL-3.0-or-later
// A tetrahedral volume mesh in patient space: shared points, tetrahedra in
// VTK's node ordering, and the label (region) each tetrahedron fills.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"

namespace labelmesh::volume_mesh {

struct TetMesh {
  // LPS, mm.
  std::vector<std::array<double, 3>> points;
  // VTK_TETRA ordering: positive signed volume, dot(p1 - p0, cross(p2 - p0, p3 - p0)) > 0, that
  // is, the right-hand normal of triangle 0,1,2 points towards node 3. Gmsh, Medit, TetGen and
  // Abaqus/CalculiX C3D4 use the same ordering.
  std::vector<std::array<uint32_t, 4>> tetrahedra;
  // One per tetrahedron: the label it fills.
  std::vector<int32_t> labels;

  // Adds the points, tetrahedra and labels of `other` as a separate piece: indices are offset,
  // no points are merged.
  void append(const TetMesh& other);
};

// Signed volume of tetrahedron `t`, in mm³: positive for VTK ordering, negative when inverted.
double signed_volume(const TetMesh& mesh, size_t t);

// One face of a label's boundary.
struct BoundaryFace {
  uint32_t tet;    // index into mesh.tetrahedra
  int32_t label;   // mesh.labels[tet]
  uint8_t across;  // local index (0-3) of the tetrahedron's vertex opposite the face
  // The face's points, wound so that the right-hand normal points out of the tetrahedron (and
  // out of the label's region).
  std::array<uint32_t, 3> points;
};

// The faces of each label's region that no other tetrahedron of the same label shares: its outer
// surface and its interfaces with other labels (an interface between two labels appears once for
// each, with opposite windings). Sorted by label, then tetrahedron, then `across`.
// Precondition: check_tet_mesh(mesh) is OK.
std::vector<BoundaryFace> label_boundary_faces(const TetMesh& mesh);

// The local vertices of the face opposite local vertex `across`, wound outwards for a
// positively oriented tetrahedron.
const std::array<uint8_t, 3>& outward_face(uint8_t across);

// INVALID_ARGUMENT when the mesh has a label count different from its tetrahedron count, or a
// tetrahedron that names a point that does not exist; OK otherwise.
absl::Status check_tet_mesh(const TetMesh& mesh);

}  // namespace labelmesh::volume_mesh
