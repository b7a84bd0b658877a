// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/surface_checks.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <memory>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/hilbert_sort.h>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/util/side_by_side.h"
#include "core/util/vec3.h"

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

}  // namespace

// The distance measurement's parts, named so that DistanceMeasurement::State
// may hold them: a type from an unnamed namespace in a member of a named
// one is a warning once files are compiled together.
namespace distance_parts {

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

}  // namespace distance_parts

namespace {
using distance_parts::Direction;
using distance_parts::OneSided;
}  // namespace

constexpr size_t kSeedEvery = 4;

struct DistanceReference::Parts {
  std::vector<Point> samples;
  Triangles triangles;
  std::unique_ptr<Tree> tree;
};

DistanceReference::DistanceReference(const TriangleMesh& mesh, double sample_spacing_mm,
                                     const RunContext& context)
    : parts_(std::make_unique<Parts>()), sample_spacing_mm_(sample_spacing_mm) {
  // A stop leaves no samples and no tree: nothing to measure, not a part.
  auto stopped = [this, &context] {
    if (!context.stop_requested()) return false;
    parts_->tree.reset();  // before the triangles it points into
    parts_->triangles = {};
    parts_->samples = {};
    return true;
  };
  parts_->samples = sample_points(mesh, sample_spacing_mm);
  if (stopped()) return;
  // Queries in Hilbert order find the tree's nodes still in cache (on the
  // liver, about a sixth less query time). Cutting cells at their middle rather
  // than at the median point sorts the samples in about a quarter less time.
  CGAL::hilbert_sort(parts_->samples.begin(), parts_->samples.end(),
                     CGAL::Hilbert_sort_middle_policy());
  if (stopped()) return;
  parts_->triangles = to_triangles(mesh);
  if (!parts_->triangles.empty()) {
    parts_->tree = std::make_unique<Tree>(parts_->triangles.begin(), parts_->triangles.end());
    parts_->tree->build();
    if (stopped()) return;
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
    // A look at a stop request every few thousand queries: cheap, and prompt.
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
  DistanceMeasurement measurement(a, b);
  side_by_side([&] { measurement.work(context); }, [&] { measurement.work(context); });
  return measurement.result();
}

// Chunks small enough that a thread joining late still finds some (each a
// short run of queries), in a fixed order: all of one direction, then the
// other.
constexpr size_t kChunkSamples = 16384;

struct DistanceMeasurement::State {
  State(const TriangleMesh& a, const DistanceReference& b)
      : a_parts(a, b.sample_spacing_mm()),
        a_to_b{a_parts.parts().samples, b.parts().tree.get()},
        b_to_a{b.parts().samples, a_parts.parts().tree.get()},
        forward_chunks(chunks_of(a_to_b)),
        chunks(forward_chunks + chunks_of(b_to_a)) {}

  static size_t chunks_of(const Direction& direction) {
    return (direction.samples.size() + kChunkSamples - 1) / kChunkSamples;
  }

  const DistanceReference a_parts;
  const Direction a_to_b, b_to_a;
  const size_t forward_chunks;
  std::vector<OneSided> chunks;
  std::atomic<size_t> next_chunk{0};
};

DistanceMeasurement::DistanceMeasurement(const TriangleMesh& a, const DistanceReference& b)
    : state_(std::make_unique<State>(a, b)) {}

DistanceMeasurement::~DistanceMeasurement() = default;

void DistanceMeasurement::work(const RunContext& context) {
  State& s = *state_;
  const size_t forward = s.forward_chunks;
  for (size_t chunk = s.next_chunk++; chunk < s.chunks.size(); chunk = s.next_chunk++) {
    if (context.stop_requested()) return;
    const bool is_forward = chunk < forward;
    const Direction& direction = is_forward ? s.a_to_b : s.b_to_a;
    const size_t begin = (is_forward ? chunk : chunk - forward) * kChunkSamples;
    const size_t end = std::min(begin + kChunkSamples, direction.samples.size());
    // Each chunk has its own slot: no two threads write the same one.
    s.chunks[chunk] = distances(direction, begin, end, context);
  }
}

SurfaceDistance DistanceMeasurement::result() const {
  const State& s = *state_;
  // Added in chunk order, so the sums do not depend on scheduling.
  OneSided forward, backward;
  for (size_t chunk = 0; chunk < s.chunks.size(); ++chunk)
    (chunk < s.forward_chunks ? forward : backward).add(s.chunks[chunk]);
  SurfaceDistance distance;
  const OneSided& worse = forward.max_squared >= backward.max_squared ? forward : backward;
  distance.hausdorff_mm = std::sqrt(worse.max_squared);
  distance.hausdorff_at = {worse.farthest.x(), worse.farthest.y(), worse.farthest.z()};
  const size_t count = forward.count + backward.count;
  distance.mean_mm = count > 0 ? (forward.sum + backward.sum) / double(count) : 0;
  return distance;
}

}  // namespace labelmesh::surface
