// SPDX-License-Identifier: AGPL-3.0-or-later
// The check that a tetrahedral mesh of several labels is conforming: faces shared by at most two
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
