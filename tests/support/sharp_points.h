// SPDX-License-Identifier: AGPL-3.0-or-later
// Points where a surface comes to a sharp tip or saddle, as a render shows
// spikes: the angles of the triangles around a point fall short of a full
// turn, or exceed it, by more than a given angle (a flat or gently curved
// surface sums to about 2 pi; the corner of a cube to 3 pi / 2). Points on
// an open rim are left out: their triangles never go round them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/surface/triangle_mesh.h"
#include "core/util/vec3.h"

namespace labelmesh::testing {

struct SharpPoints {
  size_t points = 0;  // points with a triangle, not on an open rim
  size_t sharp = 0;   // of those, sharper than the limit
};

inline SharpPoints sharp_points(const surface::TriangleMesh& mesh, double deficit_rad) {
  const size_t n = mesh.points.size();
  std::vector<double> angle(n, 0);
  std::vector<bool> used(n, false);
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto& a = mesh.points[t[k]];
      angle[t[k]] += geometry::angle_between(geometry::sub(mesh.points[t[(k + 1) % 3]], a),
                                             geometry::sub(mesh.points[t[(k + 2) % 3]], a));
      used[t[k]] = true;
      edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
    }
  }
  // An edge of one triangle only lies on an open rim.
  std::sort(edges.begin(), edges.end());
  std::vector<bool> on_rim(n, false);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) on_rim[edges[i].first] = on_rim[edges[i].second] = true;
    i = j;
  }
  SharpPoints found;
  for (size_t p = 0; p < n; ++p) {
    if (!used[p] || on_rim[p]) continue;
    ++found.points;
    if (std::abs(2 * M_PI - angle[p]) > deficit_rad) ++found.sharp;
  }
  return found;
}

}  // namespace labelmesh::testing
