// SPDX-License-Identifier: AGPL-3.0-or-later
// The faces where labels meet in a conforming tetrahedral mesh of several
// labels, and the check that the mesh is one: faces shared by at most two
// tetrahedra, no repeated points, every label's region closed, and no overlap
// or gap between the labels.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/volume_mesh/tet_mesh.h"

namespace labelmesh::conforming {

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

struct ConformityCheck {
  size_t tetrahedra = 0;
  size_t points = 0;
  size_t interior_faces = 0;   // shared by two tetrahedra of one label
  size_t interface_faces = 0;  // shared by two tetrahedra of different labels
  size_t outer_faces = 0;      // one tetrahedron's only
  size_t interfaces = 0;       // distinct label pairs, the outside included
  // Each of these is 0 in a conforming mesh.
  size_t overshared_faces = 0;       // faces of three or more tetrahedra
  size_t inverted_tetrahedra = 0;    // signed volume <= 0
  size_t duplicate_points = 0;       // points at the same coordinates as another
  size_t unused_points = 0;          // points no tetrahedron uses
  size_t open_boundary_edges = 0;    // edges of the outer boundary used by an odd number of faces
  size_t unlabelled_tetrahedra = 0;  // label 0 (the outside)
  // The labels' volumes added up, and the volume the outer boundary encloses:
  // equal when nothing overlaps and nothing is missing.
  double label_volume_sum_mm3 = 0;
  double union_volume_mm3 = 0;

  double volume_gap_fraction() const;
  bool ok() const;
  // What failed, for an error message; empty when ok().
  std::string failures() const;
};

ConformityCheck check_conforming_mesh(const volume_mesh::TetMesh& mesh);

}  // namespace labelmesh::conforming
