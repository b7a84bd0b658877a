#include "core/surface/surface_checks.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <thread>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include "core/geometry/vec3.h"
#include "core/surface/cgal_mesh.h"

namespace labelmesh::surface {
namespace {

using cgal::Kernel;
using cgal::Point;
using Triangle = Kernel::Triangle_3;
using Triangles = std::vector<Triangle>;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Triangles to_triangles(const TriangleMesh& mesh) {
  Triangles triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    triangles.emplace_back(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]),
                           Point(c[0], c[1], c[2]));
  }
  return triangles;
}

// Every vertex of `mesh`, plus, on triangles longer than `spacing`, the points
// of a barycentric grid whose neighbours are no further apart than `spacing`.
std::vector<Point> sample_points(const TriangleMesh& mesh, double spacing) {
  std::vector<Point> samples = cgal::to_points(mesh);
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const double longest =
        std::max({geometry::norm(geometry::sub(a, b)), geometry::norm(geometry::sub(b, c)),
                  geometry::norm(geometry::sub(c, a))});
    const int steps = static_cast<int>(std::ceil(longest / spacing));
    if (steps < 2) continue;
    for (int i = 0; i <= steps; ++i) {
      for (int j = 0; i + j <= steps; ++j) {
        const int k = steps - i - j;
        if ((i == steps) || (j == steps) || (k == steps)) continue;  // the corners
        const double u = double(i) / steps, v = double(j) / steps, w = double(k) / steps;
        samples.emplace_back(u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
                             u * a[2] + v * b[2] + w * c[2]);
      }
    }
  }
  return samples;
}

struct OneSided {
  double max_squared = 0;
  Point farthest = Point(0, 0, 0);
  double sum = 0;
  size_t count = 0;
};

OneSided distances_to(const std::vector<Point>& samples, const Triangles& target) {
  OneSided result;
  if (target.empty()) return result;
  Tree tree(target.begin(), target.end());
  tree.accelerate_distance_queries();
  for (const Point& p : samples) {
    const double squared = CGAL::to_double(tree.squared_distance(p));
    if (squared > result.max_squared) {
      result.max_squared = squared;
      result.farthest = p;
    }
    result.sum += std::sqrt(squared);
    ++result.count;
  }
  return result;
}

}  // namespace

std::optional<uint64_t> count_self_intersections(const TriangleMesh& mesh) {
  auto built = cgal::to_surface_mesh(mesh);
  if (!built) return std::nullopt;
  std::vector<std::pair<cgal::Mesh::Face_index, cgal::Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(*built, std::back_inserter(pairs));
  return pairs.size();
}

SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleMesh& b,
                                 double sample_spacing_mm) {
  // The two directions are independent: run one on a second thread. Each sum
  // runs in a fixed order, so the figures do not depend on scheduling.
  OneSided a_to_b;
  std::thread forward(
      [&] { a_to_b = distances_to(sample_points(a, sample_spacing_mm), to_triangles(b)); });
  const OneSided b_to_a = distances_to(sample_points(b, sample_spacing_mm), to_triangles(a));
  forward.join();
  SurfaceDistance distance;
  const OneSided& worse = a_to_b.max_squared >= b_to_a.max_squared ? a_to_b : b_to_a;
  distance.hausdorff_mm = std::sqrt(worse.max_squared);
  distance.hausdorff_at = {worse.farthest.x(), worse.farthest.y(), worse.farthest.z()};
  const size_t count = a_to_b.count + b_to_a.count;
  distance.mean_mm = count > 0 ? (a_to_b.sum + b_to_a.sum) / double(count) : 0;
  return distance;
}

}  // namespace labelmesh::surface
