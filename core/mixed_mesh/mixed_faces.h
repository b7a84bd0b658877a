// SPDX-License-Identifier: AGPL-3.0-or-later
// The faces of mixed cells, in VTK's face tables (vtkHexahedron, vtkWedge, vtkPyramid,
// vtkTetra::GetFaceArray), and the faces of each label's region. The conformity check and the
// Medit and Abaqus writers share them.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/mixed_mesh/mixed_mesh.h"

namespace labelmesh::mixed_mesh {

// One face of a cell type: 3 or 4 local node indices, wound so that the right-hand normal points
// out of a valid cell (nodes[3] is unused for triangles).
struct LocalFace {
  uint8_t size;
  std::array<uint8_t, 4> nodes;
};

// The faces of `type`, in VTK's order: hexahedron 6 quads; wedge 2 triangles then 3 quads;
// pyramid the base quad then 4 triangles; tetrahedron 4 triangles.
std::span<const LocalFace> local_faces(CellType type);

// The corners of hexahedron face `f` (local_faces order) wound the other way, so that the
// right-hand normal points into the cell: the base of a pyramid whose apex is inside.
std::array<uint8_t, 4> hexahedron_face_inward(int f);

// One face of one cell, with mesh point indices.
struct CellFace {
  uint32_t cell;  // index into the mesh's cells
  uint8_t local;  // index into local_faces(type of the cell)
  uint8_t size;   // 3 or 4
  // Wound outwards for a valid cell; points[3] is unused for triangles.
  std::array<uint32_t, 4> points;

  // The point set, sorted, with kNone in place of a triangle's missing fourth point: two faces
  // over the same points have the same key.
  std::array<uint32_t, 4> key() const;
  static constexpr uint32_t kNone = UINT32_MAX;
};

// Every face of every cell, cell by cell in local_faces order.
// Precondition: check_mixed_mesh(mesh) is OK.
std::vector<CellFace> cell_faces(const MixedMesh& mesh);

// The faces of each label's region that no other cell of the same label shares (same point set):
// its outer surface and its interfaces with other labels, each wound out of the label's region.
// Sorted by label, then cell, then local face. Faces that only partly match (a quad against two
// triangles) are all kept. Precondition: check_mixed_mesh(mesh) is OK.
std::vector<CellFace> label_boundary_faces(const MixedMesh& mesh);

}  // namespace labelmesh::mixed_mesh
