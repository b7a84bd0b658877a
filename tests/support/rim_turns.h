// SPDX-License-Identifier: AGPL-3.0-or-later
// How smoothly the rims of a surface's flat caps on the volume's edge run:
// at each rim point, the angle between its two rim edges (0 on a straight
// or gently curved rim, 90 degrees at the corner of a pixel step).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "core/header/image_geometry.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/vec3.h"

namespace labelmesh::testing {

struct RimTurns {
  size_t points = 0;  // rim points with exactly two rim edges
  double sum_deg = 0;
  size_t over_30_deg = 0;
};

// Adds `mesh`'s rim points to `sum`. A point lies on an edge plane when its
// index along an axis of `geometry` is -1/2 or the last voxel's plus 1/2; a
// cap triangle has its three points on one plane, and a rim edge is a cap
// triangle's edge that a triangle off the cap shares. Read from delivered
// surfaces, the measure is approximate: a rim point the angle widening slid
// off the plane breaks its rim there, and on thick slices a wall point held
// at the edge by its wide box counts as on the cap.
inline void add_rim_turns(const surface::TriangleMesh& mesh, const volume::ImageGeometry& geometry,
                          RimTurns& sum) {
  constexpr double kOnPlane = 1e-6;  // voxels
  // Per point, a bit per plane: 2 k for the low side of axis k, 2 k + 1 for the high.
  std::vector<uint8_t> planes(mesh.points.size(), 0);
  for (size_t p = 0; p < mesh.points.size(); ++p) {
    const auto index = geometry.to_index(mesh.points[p]);
    for (int k = 0; k < 3; ++k) {
      if (std::abs(index[k] + 0.5) < kOnPlane) planes[p] |= uint8_t(1u << (2 * k));
      if (std::abs(index[k] - (double(geometry.dims[k]) - 0.5)) < kOnPlane)
        planes[p] |= uint8_t(1u << (2 * k + 1));
    }
  }
  // Each edge: whether a cap triangle has it, whether another triangle does.
  std::map<std::pair<uint32_t, uint32_t>, std::array<bool, 2>> edges;
  for (const auto& t : mesh.triangles) {
    const bool cap = (planes[t[0]] & planes[t[1]] & planes[t[2]]) != 0;
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(t[k], t[(k + 1) % 3]);
      edges[{key.first, key.second}][cap ? 0 : 1] = true;
    }
  }
  std::map<uint32_t, std::vector<uint32_t>> along;
  for (const auto& [edge, sides] : edges) {
    if (!sides[0] || !sides[1]) continue;
    along[edge.first].push_back(edge.second);
    along[edge.second].push_back(edge.first);
  }
  for (const auto& [p, ends] : along) {
    if (ends.size() != 2) continue;
    const geometry::Vec3 in = geometry::sub(mesh.points[p], mesh.points[ends[0]]);
    const geometry::Vec3 out = geometry::sub(mesh.points[ends[1]], mesh.points[p]);
    if (geometry::norm(in) * geometry::norm(out) <= 0) continue;
    const double turn = geometry::angle_between(in, out) * 180 / M_PI;
    ++sum.points;
    sum.sum_deg += turn;
    if (turn > 30) ++sum.over_30_deg;
  }
}

}  // namespace labelmesh::testing
