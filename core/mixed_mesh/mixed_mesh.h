// SPDX-License-Identifier: AGPL-3.0-or-later
// A volume mesh of mixed elements in patient space: hexahedra inside, and
// pyramids, wedges and tetrahedra where the hexahedra meet the surface.
// Every cell lists its nodes in VTK's ordering (VTK_HEXAHEDRON, VTK_PYRAMID,
// VTK_WEDGE, VTK_TETRA; see core/quality/element_quality.h), so a valid
// cell has positive corner Jacobians.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace labelmesh::mixed_mesh {

// The value is the cell's node count.
enum class CellType : uint8_t { kTetra = 4, kPyramid = 5, kWedge = 6, kHexahedron = 8 };

inline int node_count(CellType type) { return static_cast<int>(type); }

struct MixedMesh {
  // LPS, mm.
  std::vector<std::array<double, 3>> points;
  // One entry per cell in each of the three: its type, its nodes (the first
  // node_count(type) entries; the rest unused) and its label.
  std::vector<CellType> types;
  std::vector<std::array<uint32_t, 8>> cells;
  std::vector<int32_t> labels;

  size_t size() const { return types.size(); }
  size_t count(CellType type) const;
  void add(CellType type, const std::array<uint32_t, 8>& nodes, int32_t label);
  // Adds `other`'s points and cells as a separate piece: indices are offset,
  // no points are merged.
  void append(const MixedMesh& other);
};

// The first N points of cell `cell`, in its node order.
template <size_t N>
std::array<std::array<double, 3>, N> cell_points(const MixedMesh& mesh, size_t cell) {
  std::array<std::array<double, 3>, N> p;
  for (size_t k = 0; k < N; ++k) p[k] = mesh.points[mesh.cells[cell][k]];
  return p;
}

}  // namespace labelmesh::mixed_mesh
