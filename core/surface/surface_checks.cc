#include "core/surface/surface_checks.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/hilbert_sort.h>

#include "core/geometry/vec3.h"
#include "core/side_by_side.h"
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

Point mix(const geometry::Vec3& a, double u, const geometry::Vec3& b, double v,
          const geometry::Vec3& c, double w) {
  return Point(u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
               u * a[2] + v * b[2] + w * c[2]);
}

// Points on `mesh` no further than about `spacing` from their neighbours:
// every vertex; evenly spaced points along each edge longer than `spacing`,
// once per edge (not once per triangle: on Marching Cubes surfaces, where
// most edges just pass the spacing, that sampled each midpoint twice); and
// the points strictly inside each triangle of a barycentric grid of
// `spacing`.
std::vector<Point> sample_points(const TriangleMesh& mesh, double spacing) {
  std::vector<Point> samples = cgal::to_points(mesh);
  auto steps_along = [spacing](const geometry::Vec3& a, const geometry::Vec3& b) {
    return static_cast<int>(std::ceil(geometry::norm(geometry::sub(a, b)) / spacing));
  };
  std::vector<uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      edges.push_back(uint64_t{std::min(a, b)} << 32 | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (uint64_t edge : edges) {
    const auto& a = mesh.points[edge >> 32];
    const auto& b = mesh.points[edge & 0xffffffffu];
    const int steps = steps_along(a, b);
    for (int i = 1; i < steps; ++i) {
      const double u = double(i) / steps;
      samples.push_back(mix(a, 1 - u, b, u, b, 0));
    }
  }
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const int steps = std::max({steps_along(a, b), steps_along(b, c), steps_along(c, a)});
    for (int i = 1; i < steps; ++i) {
      for (int j = 1; i + j < steps; ++j) {
        const int k = steps - i - j;
        samples.push_back(mix(a, double(i) / steps, b, double(j) / steps, c, double(k) / steps));
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

  void add(const OneSided& later) {
    if (later.max_squared > max_squared) {
      max_squared = later.max_squared;
      farthest = later.farthest;
    }
    sum += later.sum;
    count += later.count;
  }
};

// One direction of the distance: where the samples are and what they are
// measured against (the samples of one surface, the tree of the other).
struct Direction {
  const std::vector<Point>& samples;
  const Tree* tree;
};

}  // namespace

constexpr size_t kSeedEvery = 4;

struct DistanceReference::Parts {
  std::vector<Point> samples;
  Triangles triangles;
  std::unique_ptr<Tree> tree;
};

DistanceReference::DistanceReference(const TriangleMesh& mesh, double sample_spacing_mm)
    : parts_(std::make_unique<Parts>()), sample_spacing_mm_(sample_spacing_mm) {
  parts_->samples = sample_points(mesh, sample_spacing_mm);
  // Queries in Hilbert order find the tree's nodes still in cache (liver:
  // 1.2 s of queries down to 1.0 s).
  CGAL::hilbert_sort(parts_->samples.begin(), parts_->samples.end());
  parts_->triangles = to_triangles(mesh);
  if (!parts_->triangles.empty()) {
    parts_->tree = std::make_unique<Tree>(parts_->triangles.begin(), parts_->triangles.end());
    parts_->tree->build();
    // The first corner of every fourth triangle seeds each query's search:
    // a quarter of CGAL's default memory, about as near a start.
    std::vector<std::pair<Point, Primitive::Id>> seeds;
    seeds.reserve(parts_->triangles.size() / kSeedEvery + 1);
    for (size_t t = 0; t < parts_->triangles.size(); t += kSeedEvery) {
      const auto id = parts_->triangles.cbegin() + std::ptrdiff_t(t);
      seeds.emplace_back(id->vertex(0), id);
    }
    parts_->tree->accelerate_distance_queries(seeds.begin(), seeds.end());
  }
}

DistanceReference::~DistanceReference() = default;

namespace {

OneSided distances(const Direction& direction, size_t begin, size_t end,
                   const RunContext& context) {
  OneSided result;
  if (direction.tree == nullptr) return result;
  for (size_t i = begin; i < end; ++i) {
    // About 10 ms of queries between looks at a stop request.
    if ((i - begin) % 4096 == 4095 && context.stop_requested()) break;
    const Point& p = direction.samples[i];
    const double squared = CGAL::to_double(direction.tree->squared_distance(p));
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
                                 double sample_spacing_mm, const RunContext& context) {
  return surface_distance(a, DistanceReference(b, sample_spacing_mm), context);
}

SurfaceDistance surface_distance(const TriangleMesh& a, const DistanceReference& b,
                                 const RunContext& context) {
  const DistanceReference a_parts(a, b.sample_spacing_mm());
  const Direction a_to_b{a_parts.parts().samples, b.parts().tree.get()};
  const Direction b_to_a{b.parts().samples, a_parts.parts().tree.get()};
  // Each thread's share is a fixed range and the partial sums are added in a
  // fixed order, so the figures do not depend on scheduling.
  // Each direction's samples are halved between the threads: per query, the
  // direction into the denser mesh costs twice the other.
  const size_t a_half = a_to_b.samples.size() / 2, b_half = b_to_a.samples.size() / 2;
  OneSided first_forward, first_backward, second_forward, second_backward;
  side_by_side(
      [&] {
        second_forward = distances(a_to_b, a_half, a_to_b.samples.size(), context);
        second_backward = distances(b_to_a, b_half, b_to_a.samples.size(), context);
      },
      [&] {
        first_forward = distances(a_to_b, 0, a_half, context);
        first_backward = distances(b_to_a, 0, b_half, context);
      });
  first_forward.add(second_forward);
  first_backward.add(second_backward);

  SurfaceDistance distance;
  const OneSided& worse =
      first_forward.max_squared >= first_backward.max_squared ? first_forward : first_backward;
  distance.hausdorff_mm = std::sqrt(worse.max_squared);
  distance.hausdorff_at = {worse.farthest.x(), worse.farthest.y(), worse.farthest.z()};
  const size_t count = first_forward.count + first_backward.count;
  distance.mean_mm = count > 0 ? (first_forward.sum + first_backward.sum) / double(count) : 0;
  return distance;
}

}  // namespace labelmesh::surface
