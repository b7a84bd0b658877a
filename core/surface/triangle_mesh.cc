// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/triangle_mesh.h"

#include <utility>

namespace labelmesh::surface {

void TriangleMesh::flip_orientation() {
  for (auto& triangle : triangles) std::swap(triangle[1], triangle[2]);
}

void TriangleMesh::append(const TriangleMesh& other) {
  const auto offset = static_cast<uint32_t>(points.size());
  points.insert(points.end(), other.points.begin(), other.points.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const auto& t : other.triangles)
    triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

}  // namespace labelmesh::surface
