// SPDX-License-Identifier: AGPL-3.0-or-later
// Conversions between TriangleMesh and CGAL's Surface_mesh. Included only by
// the CGAL translation units (see core/CMakeLists.txt).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>

#include "core/surface/surface_statistics.h"
#include "core/surface/triangle_mesh.h"

namespace labelmesh::surface::cgal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

inline std::vector<Point> to_points(const TriangleMesh& mesh) {
  std::vector<Point> points;
  points.reserve(mesh.points.size());
  for (const auto& p : mesh.points) points.emplace_back(p[0], p[1], p[2]);
  return points;
}

// nullopt when the triangles do not form a valid polygon mesh (a non-manifold
// edge or vertex, or inconsistent orientation).
inline std::optional<Mesh> to_surface_mesh(const TriangleMesh& mesh) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  if (!is_oriented_manifold(mesh)) return std::nullopt;
  Mesh result;
  PMP::polygon_soup_to_polygon_mesh(to_points(mesh), mesh.triangles, result);
  return result;
}

// Vertices in index order; `mesh` must hold no removed elements.
inline TriangleMesh from_surface_mesh(const Mesh& mesh) {
  TriangleMesh result;
  result.points.reserve(mesh.number_of_vertices());
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    result.points.push_back({p.x(), p.y(), p.z()});
  }
  result.triangles.reserve(mesh.number_of_faces());
  for (auto f : mesh.faces()) {
    std::array<uint32_t, 3> triangle{};
    size_t corner = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (corner < 3) triangle[corner] = static_cast<uint32_t>(v.idx());
      ++corner;
    }
    if (corner == 3) result.triangles.push_back(triangle);
  }
  return result;
}

}  // namespace labelmesh::surface::cgal
