// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/net_label_surface.h"

#include <algorithm>
#include <vector>

#include "core/util/disjoint_sets.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// One triangle's use of one of its edges.
struct EdgeUse {
  uint64_t key = 0;    // the edge's two points, lower id first
  uint64_t voxel = 0;  // the label's voxel the triangle bounds
  uint32_t triangle = 0;
  bool forward = false;  // the triangle runs the edge from the lower id
};

// The corner (3 t + k) of triangle t at `point`.
uint32_t corner_at(const std::vector<std::array<uint32_t, 3>>& triangles, uint32_t t,
                   uint32_t point) {
  const auto& tri = triangles[t];
  const int k = tri[0] == point ? 0 : (tri[1] == point ? 1 : 2);
  return 3 * t + static_cast<uint32_t>(k);
}

// Corners (3 per triangle) joined across the edges the surface crosses
// smoothly: each class is one fan of triangles around a point. On an edge of
// more than two triangles (the label's voxels meet only along it) the two
// triangles around each voxel stay together, except on the edges in
// `connect`, where each voxel's triangle joins the other voxel's that runs
// the edge the other way. `uses` is sorted by edge, then voxel.
geometry::DisjointSets fan_classes(const std::vector<std::array<uint32_t, 3>>& triangles,
                                   const std::vector<EdgeUse>& uses,
                                   const std::vector<uint64_t>& connect) {
  geometry::DisjointSets corners(3 * triangles.size());
  const auto join = [&](uint64_t key, uint32_t t1, uint32_t t2) {
    const auto a = static_cast<uint32_t>(key >> 32), b = static_cast<uint32_t>(key);
    corners.unite(corner_at(triangles, t1, a), corner_at(triangles, t2, a));
    corners.unite(corner_at(triangles, t1, b), corner_at(triangles, t2, b));
  };
  for (size_t first = 0; first < uses.size();) {
    size_t last = first;
    const uint64_t key = uses[first].key;
    while (last < uses.size() && uses[last].key == key) ++last;
    if (last - first == 2) {
      join(key, uses[first].triangle, uses[first + 1].triangle);
    } else if (last - first == 4 && std::binary_search(connect.begin(), connect.end(), key)) {
      // Two voxels, two triangles each: join across the voxels.
      for (size_t i = first; i < first + 2; ++i)
        for (size_t j = first + 2; j < last; ++j)
          if (uses[i].forward != uses[j].forward) join(key, uses[i].triangle, uses[j].triangle);
    } else {
      for (size_t i = first + 1; i < last; ++i) {
        if (uses[i].voxel == uses[i - 1].voxel) join(key, uses[i - 1].triangle, uses[i].triangle);
      }
    }
    first = last;
  }
  return corners;
}

// The net edges (keys) whose triangles still share one edge of output points
// three or more times once each fan class is its own point. A class belongs
// to one net point, so only a net edge with more than two uses can be one:
// those are the groups of `uses` (sorted by edge) longer than two.
std::vector<uint64_t> edges_used_more_than_twice(
    const std::vector<std::array<uint32_t, 3>>& triangles, const std::vector<EdgeUse>& uses,
    geometry::DisjointSets& corners) {
  std::vector<uint64_t> keys;
  std::vector<uint64_t> class_pairs;
  for (size_t first = 0; first < uses.size();) {
    size_t last = first;
    const uint64_t key = uses[first].key;
    while (last < uses.size() && uses[last].key == key) ++last;
    if (last - first > 2) {
      const auto a = static_cast<uint32_t>(key >> 32), b = static_cast<uint32_t>(key);
      class_pairs.clear();
      for (size_t i = first; i < last; ++i) {
        const uint32_t t = uses[i].triangle;
        class_pairs.push_back((uint64_t{corners.find(corner_at(triangles, t, a))} << 32) |
                              corners.find(corner_at(triangles, t, b)));
      }
      std::sort(class_pairs.begin(), class_pairs.end());
      for (size_t i = 2; i < class_pairs.size(); ++i)
        if (class_pairs[i] == class_pairs[i - 2]) {
          keys.push_back(key);
          break;
        }
    }
    first = last;
  }
  return keys;
}

// The label's voxel centre of a padded linear index, LPS mm.
Vec3 voxel_centre(uint64_t padded, const InterfaceSurface& net,
                  const volume::ImageGeometry& geometry) {
  const auto v = static_cast<int64_t>(padded);
  const auto& dims = net.padded_dims;
  const auto& first = net.padded_first;
  const double x = double(v % dims[0] + first[0]);
  const double y = double((v / dims[0]) % dims[1] + first[1]);
  const double z = double(v / (dims[0] * dims[1]) + first[2]);
  return geometry.to_physical({x, y, z});
}

}  // namespace

NetLabelSurface net_label_surface(const InterfaceSurface& net, int32_t label,
                                  const volume::ImageGeometry& geometry,
                                  SplitCrossings split_crossings) {
  // The label's triangles, wound outward, and the voxel each bounds.
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint64_t> voxel;
  std::vector<uint32_t> net_triangles;
  for (size_t t = 0; t < net.triangles.size(); ++t) {
    const auto& sides = net.sides[t];
    if (sides[0] != label && sides[1] != label) continue;
    auto triangle = net.triangles[t];
    // Normals point from sides[0] into sides[1]: outward when the label is
    // behind.
    const bool behind = sides[0] == label;
    if (!behind) std::swap(triangle[1], triangle[2]);
    triangles.push_back(triangle);
    voxel.push_back(net.side_voxels[t][behind ? 0 : 1]);
    net_triangles.push_back(static_cast<uint32_t>(t));
  }
  NetLabelSurface result;
  result.net_triangles = std::move(net_triangles);
  if (triangles.empty()) return result;

  std::vector<EdgeUse> uses;
  uses.reserve(3 * triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      const uint64_t key = a < b ? (uint64_t{a} << 32) | b : (uint64_t{b} << 32) | a;
      uses.push_back({key, voxel[t], t, a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key
                          : (x.voxel != y.voxel ? x.voxel < y.voxel : x.triangle < y.triangle);
  });
  std::vector<uint64_t> connect;  // edges where the voxels are joined, sorted
  geometry::DisjointSets corners = fan_classes(triangles, uses, connect);
  // An edge whose two voxels the surface joins around both its ends
  // anyway still has four triangles once the points are split: there the
  // voxels are joined along the edge too, which keeps it manifold.
  connect = edges_used_more_than_twice(triangles, uses, corners);
  if (!connect.empty()) corners = fan_classes(triangles, uses, connect);

  // One output point per class; where a net point has several, each copy
  // moves a little towards the voxels of its own fan.
  std::vector<uint32_t> class_point(3 * triangles.size(), UINT32_MAX);
  std::vector<uint32_t> copies(net.points.size(), 0);
  std::vector<uint32_t> source;  // net point of each output point
  std::vector<Vec3> voxel_sum;
  std::vector<uint32_t> voxel_count;
  auto& mesh = result.mesh;
  auto& staircase = result.staircase;
  mesh.triangles.resize(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) {
    const Vec3 centre = voxel_centre(voxel[t], net, geometry);
    for (int k = 0; k < 3; ++k) {
      const uint32_t root = corners.find(3 * t + static_cast<uint32_t>(k));
      if (class_point[root] == UINT32_MAX) {
        class_point[root] = static_cast<uint32_t>(source.size());
        source.push_back(triangles[t][k]);
        ++copies[triangles[t][k]];
        voxel_sum.push_back({0, 0, 0});
        voxel_count.push_back(0);
      }
      const uint32_t p = class_point[root];
      mesh.triangles[t][k] = p;
      voxel_sum[p] = geometry::add(voxel_sum[p], centre);
      ++voxel_count[p];
    }
  }
  // A copy `fraction` of the way from its net point towards its voxels.
  const auto nudged = [&](size_t p, double fraction) {
    const Vec3& at = net.points[source[p]];
    const Vec3 towards = geometry::scale(voxel_sum[p], 1.0 / voxel_count[p]);
    return geometry::add(at, geometry::scale(geometry::sub(towards, at), fraction));
  };
  mesh.points.resize(source.size());
  staircase.points.resize(source.size());
  for (size_t p = 0; p < source.size(); ++p) {
    mesh.points[p] = net.points[source[p]];
    staircase.points[p] = net.staircase[source[p]];
    if (copies[source[p]] < 2) continue;
    ++result.split_points;
    mesh.points[p] = nudged(p, kSplitNudge);
  }
  staircase.triangles = mesh.triangles;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (const uint32_t p : mesh.triangles[t])
      if (copies[source[p]] >= 2) {
        result.moved_triangles.push_back(t);
        break;
      }
  if (split_crossings == SplitCrossings::kLeave) return result;
  // Where two moved triangles still pass through each other, the copies in
  // them move twice as far; a doubling that leaves more crossing pairs is
  // taken back, and the parting stops.
  std::vector<double> fraction(source.size(), kSplitNudge);
  const auto crossing_pairs = [&] {
    return surface::crossing_triangles_near(mesh.points, mesh.triangles, result.moved_triangles);
  };
  auto pairs = crossing_pairs();
  for (int doubling = 0; doubling < kSplitNudgeDoublings && !pairs.empty(); ++doubling) {
    std::vector<uint32_t> crossing;
    for (const auto& [a, b] : pairs) {
      if (!std::binary_search(result.moved_triangles.begin(), result.moved_triangles.end(), a) ||
          !std::binary_search(result.moved_triangles.begin(), result.moved_triangles.end(), b))
        continue;
      for (const uint32_t t : {a, b})
        for (const uint32_t p : mesh.triangles[t])
          if (copies[source[p]] >= 2) crossing.push_back(p);
    }
    if (crossing.empty()) break;
    std::sort(crossing.begin(), crossing.end());
    crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
    std::vector<Vec3> before;
    before.reserve(crossing.size());
    for (const uint32_t p : crossing) {
      before.push_back(mesh.points[p]);
      mesh.points[p] = nudged(p, 2 * fraction[p]);
    }
    auto after = crossing_pairs();
    if (after.size() > pairs.size()) {
      for (size_t i = 0; i < crossing.size(); ++i) mesh.points[crossing[i]] = before[i];
      break;
    }
    for (const uint32_t p : crossing) fraction[p] *= 2;
    pairs = std::move(after);
  }
  result.split_crossings = pairs.size();
  return result;
}

uint64_t net_label_self_intersections(const InterfaceSurface& net,
                                      const surface::TrianglePairs& net_crossings,
                                      const NetLabelSurface& cut, int32_t label) {
  std::vector<uint32_t> moved;
  moved.reserve(cut.moved_triangles.size());
  for (const uint32_t t : cut.moved_triangles) moved.push_back(cut.net_triangles[t]);
  std::sort(moved.begin(), moved.end());
  const auto kept = [&](uint32_t t) {
    const auto& sides = net.sides[t];
    return (sides[0] == label || sides[1] == label) &&
           !std::binary_search(moved.begin(), moved.end(), t);
  };
  uint64_t count = 0;
  for (const auto& [a, b] : net_crossings)
    if (kept(a) && kept(b)) ++count;
  return count + cut.split_crossings;
}

}  // namespace labelmesh::conforming
