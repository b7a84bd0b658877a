#include "core/surface/triangle_mesh.h"

#include <utility>

namespace labelmesh::surface {

void TriangleMesh::flip_orientation() {
  for (auto& triangle : triangles) std::swap(triangle[1], triangle[2]);
}

}  // namespace labelmesh::surface
