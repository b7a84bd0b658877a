// SPDX-License-Identifier: AGPL-3.0-or-later
// A tetrahedral volume mesh in patient space: shared points, tetrahedra in
// VTK's node ordering, and the label (region) each tetrahedron fills.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/status.h"
#include "core/quality/element_quality.h"

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

// A tetrahedron's face: the node opposite it.
struct FaceUse {
  uint32_t tet;
  uint8_t across;
};

// Calls `visit(uses, count)` once for each distinct face of the mesh (three
// points), with the tetrahedra that have it: one on the boundary, two inside,
// more only in a broken mesh. Uses are in tetrahedron order.
void for_each_face(const TetMesh& mesh, const std::function<void(const FaceUse*, size_t)>& visit);

// The points of a tetrahedron's face, wound out of the tetrahedron.
std::array<uint32_t, 3> face_points(const TetMesh& mesh, const FaceUse& use);

// A face between two labels, or between a label and the outside (label 0),
// listed once.
struct InterfaceFace {
  // Wound so the right-hand normal points out of `tet`, into labels[1].
  std::array<uint32_t, 3> points;
  // {label of `tet`, label across}. Between two labels the smaller comes
  // first; on the outer boundary the second is 0.
  std::array<int32_t, 2> labels;
  uint32_t tet;
  uint8_t across;  // local index of the tetrahedron's node opposite the face
};

// Every interface face, sorted by label pair, then tetrahedron and face.
std::vector<InterfaceFace> interface_faces(const volume_mesh::TetMesh& mesh);

// The distinct label pairs of `faces`, in order: interface i is pairs[i].
std::vector<std::array<int32_t, 2>> interface_pairs(const std::vector<InterfaceFace>& faces);

// Q = 1/A_gamma and the dihedral range of every tetrahedron, summed up;
// `per_tetrahedron`, when given, receives each Q in mesh order.
quality::QualitySummary summarise_quality(const TetMesh& mesh,
                                          std::vector<double>* per_tetrahedron = nullptr);

// INVALID_ARGUMENT when the mesh has a label count different from its tetrahedron count, or a
// tetrahedron that names a point that does not exist; OK otherwise.
absl::Status check_tet_mesh(const TetMesh& mesh);

}  // namespace labelmesh::volume_mesh
