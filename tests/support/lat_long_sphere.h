// SPDX-License-Identifier: AGPL-3.0-or-later
// A closed sphere of radius 10 mm about the origin from a longitude-latitude
// grid: a pole point at each end, `rings` bands and `segments` around.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/surface/triangle_mesh.h"

namespace labelmesh::testing {

inline surface::TriangleMesh lat_long_sphere(int rings, int segments) {
  surface::TriangleMesh m;
  m.points.push_back({0, 0, 10});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / segments;
      m.points.push_back({10 * std::sin(theta) * std::cos(phi),
                          10 * std::sin(theta) * std::sin(phi), 10 * std::cos(theta)});
    }
  m.points.push_back({0, 0, -10});
  const auto at = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + s % segments); };
  const auto south = uint32_t(m.points.size() - 1);
  for (int s = 0; s < segments; ++s) {
    m.triangles.push_back({0, at(1, s), at(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      m.triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
    m.triangles.push_back({at(rings - 1, s), south, at(rings - 1, s + 1)});
  }
  return m;
}

}  // namespace labelmesh::testing
