// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/mixed_mesh.h"

#include <algorithm>

namespace labelmesh::mixed_mesh {

size_t MixedMesh::count(CellType type) const {
  return static_cast<size_t>(std::count(types.begin(), types.end(), type));
}

void MixedMesh::add(CellType type, const std::array<uint32_t, 8>& nodes, int32_t label) {
  types.push_back(type);
  cells.push_back(nodes);
  labels.push_back(label);
}

void MixedMesh::append(const MixedMesh& other) {
  const auto offset = static_cast<uint32_t>(points.size());
  points.insert(points.end(), other.points.begin(), other.points.end());
  for (size_t c = 0; c < other.size(); ++c) {
    std::array<uint32_t, 8> nodes = other.cells[c];
    for (int k = 0; k < node_count(other.types[c]); ++k) nodes[k] += offset;
    add(other.types[c], nodes, other.labels[c]);
  }
}

}  // namespace labelmesh::mixed_mesh
