// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/vertex_normals.h"

namespace labelmesh::surface {

namespace {

void normalise(std::vector<geometry::Vec3>& normals) {
  for (auto& n : normals) {
    const double length = geometry::norm(n);
    n = length > 0 ? geometry::scale(n, 1 / length) : geometry::Vec3{0, 0, 0};
  }
}

}  // namespace

std::vector<geometry::Vec3> vertex_normals(const TriangleMesh& mesh, NormalWeighting weighting) {
  using geometry::Vec3;
  std::vector<Vec3> normals(mesh.points.size(), Vec3{0, 0, 0});
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.points[t[0]];
    // Twice the area, along the normal: area weighting as it comes.
    Vec3 n =
        geometry::cross(geometry::sub(mesh.points[t[1]], a), geometry::sub(mesh.points[t[2]], a));
    if (weighting == NormalWeighting::kUniform) {
      const double length = geometry::norm(n);
      if (length == 0) continue;
      n = geometry::scale(n, 1 / length);
    }
    for (uint32_t v : t) normals[v] = geometry::add(normals[v], n);
  }
  normalise(normals);
  return normals;
}

}  // namespace labelmesh::surface
