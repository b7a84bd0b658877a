// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/surface_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "core/util/disjoint_sets.h"
#include "core/util/vec3.h"

namespace labelmesh::surface {
namespace {

using geometry::cross;
using geometry::dot;
using geometry::norm;
using geometry::sub;
using Vec = geometry::Vec3;

// Angle between two edge vectors, degrees.
double angle_deg(const Vec& u, const Vec& v) {
  return geometry::angle_between(u, v) * 180.0 / std::numbers::pi;
}

using geometry::DisjointSets;

// A reference point near the surface keeps the volume sum well conditioned.
Vec centre_of(const TriangleMesh& mesh) {
  Vec lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
         std::numeric_limits<double>::max()};
  Vec hi{-lo[0], -lo[1], -lo[2]};
  for (const auto& p : mesh.points) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], p[c]);
      hi[c] = std::max(hi[c], p[c]);
    }
  }
  return mesh.points.empty() ? Vec{0, 0, 0}
                             : Vec{(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
}

// Counts vertices whose link (the edges opposite them) is not one path or cycle.
uint32_t count_non_manifold_vertices(const TriangleMesh& mesh) {
  const size_t n = mesh.points.size();
  std::vector<uint32_t> offsets(n + 1, 0);
  for (const auto& t : mesh.triangles) {
    for (uint32_t v : t) ++offsets[v + 1];
  }
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<std::array<uint32_t, 2>> links(offsets.back());
  std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& t : mesh.triangles) {
    links[fill[t[0]]++] = {t[1], t[2]};
    links[fill[t[1]]++] = {t[2], t[0]};
    links[fill[t[2]]++] = {t[0], t[1]};
  }
  uint32_t count = 0;
  std::vector<uint32_t> local, parent;
  for (size_t v = 0; v < n; ++v) {
    if (offsets[v] == offsets[v + 1]) continue;
    local.clear();
    for (uint32_t e = offsets[v]; e < offsets[v + 1]; ++e) {
      local.push_back(links[e][0]);
      local.push_back(links[e][1]);
    }
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    parent.resize(local.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto slot = [&](uint32_t id) {
      return static_cast<uint32_t>(std::lower_bound(local.begin(), local.end(), id) -
                                   local.begin());
    };
    auto root = [&](uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    size_t groups = local.size();
    for (uint32_t e = offsets[v]; e < offsets[v + 1]; ++e) {
      const uint32_t a = root(slot(links[e][0])), b = root(slot(links[e][1]));
      if (a != b) {
        parent[b] = a;
        --groups;
      }
    }
    if (groups > 1) ++count;
  }
  return count;
}

}  // namespace

bool is_oriented_manifold(const TriangleMesh& mesh) {
  std::vector<uint64_t> directed;
  directed.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return false;
    for (int e = 0; e < 3; ++e) directed.push_back(uint64_t{t[e]} << 32 | t[(e + 1) % 3]);
  }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
  return count_non_manifold_vertices(mesh) == 0;
}

double signed_volume(const TriangleMesh& mesh) {
  const Vec o = centre_of(mesh);
  double six_volume = 0;
  for (const auto& t : mesh.triangles) {
    const Vec a = sub(mesh.points[t[0]], o), b = sub(mesh.points[t[1]], o),
              c = sub(mesh.points[t[2]], o);
    six_volume += dot(a, cross(b, c));
  }
  return six_volume / 6.0;
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const auto &p0 = mesh.points[t[0]], &p1 = mesh.points[t[1]], &p2 = mesh.points[t[2]];
    area += 0.5 * norm(cross(sub(p1, p0), sub(p2, p0)));
  }
  return area;
}

SurfaceStatistics compute_surface_statistics(const TriangleMesh& mesh) {
  SurfaceStatistics s;
  s.nodes = static_cast<uint32_t>(mesh.points.size());
  s.triangles = static_cast<uint32_t>(mesh.triangles.size());
  if (mesh.triangles.empty()) return s;

  s.min_angle_deg = 180;
  s.max_angle_deg = 0;
  std::vector<uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  std::vector<char> used(mesh.points.size(), 0);
  DisjointSets sets(mesh.points.size());
  for (const auto& t : mesh.triangles) {
    const Vec& p0 = mesh.points[t[0]];
    const Vec& p1 = mesh.points[t[1]];
    const Vec& p2 = mesh.points[t[2]];
    const double angles[3] = {angle_deg(sub(p1, p0), sub(p2, p0)),
                              angle_deg(sub(p2, p1), sub(p0, p1)),
                              angle_deg(sub(p0, p2), sub(p1, p2))};
    for (double a : angles) {
      s.min_angle_deg = std::min(s.min_angle_deg, a);
      s.max_angle_deg = std::max(s.max_angle_deg, a);
    }
    if (std::min({angles[0], angles[1], angles[2]}) < kWellShapedDeg) ++s.triangles_below_30_deg;
    s.area_mm2 += 0.5 * norm(cross(sub(p1, p0), sub(p2, p0)));
    for (int e = 0; e < 3; ++e) {
      // The edge's points, lower first, and in the lowest bit which way
      // the triangle runs it (point ids stay below 2^31: a mesh that large
      // would not fit in memory).
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      edges.push_back(uint64_t{std::min(a, b)} << 33 | uint64_t{std::max(a, b)} << 1 |
                      (a > b ? 1u : 0u));
      used[a] = 1;
    }
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  std::sort(edges.begin(), edges.end());
  int64_t unique_edges = 0;
  uint32_t wound_alike = 0;  // edges of two triangles that run them the same way
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j] >> 1 == edges[i] >> 1) ++j;
    ++unique_edges;
    if (j - i == 1) ++s.boundary_edges;
    if (j - i == 2 && edges[i] == edges[i + 1]) ++wound_alike;
    if (j - i > 2) ++s.non_manifold_edges;
    i = j;
  }
  int64_t used_vertices = 0;
  for (size_t v = 0; v < used.size(); ++v) {
    if (!used[v]) continue;
    ++used_vertices;
    if (sets.find(static_cast<uint32_t>(v)) == v) ++s.components;
  }
  s.non_manifold_vertices = count_non_manifold_vertices(mesh);
  s.closed = s.boundary_edges == 0;
  s.manifold = s.non_manifold_edges == 0 && s.non_manifold_vertices == 0;
  s.consistently_wound = wound_alike == 0;
  s.euler_characteristic =
      used_vertices - unique_edges + static_cast<int64_t>(mesh.triangles.size());
  s.volume_mm3 = signed_volume(mesh);
  return s;
}

}  // namespace labelmesh::surface
