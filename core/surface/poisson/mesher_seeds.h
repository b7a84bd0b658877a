// SPDX-License-Identifier: AGPL-3.0-or-later
// Where the surface mesher starts: points of the zero level spread over the
// whole surface. Included only by the Poisson translation unit and its test:
// CGAL's Poisson and surface mesher headers are slow to compile.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <CGAL/hilbert_sort.h>

#include "core/surface/poisson/zero_level_oracle.h"

namespace labelmesh::surface::poisson {

// CGAL's surface mesher starts from a few points found along rays from a
// point inside and refines from there, one point at a time: each insertion
// asks the oracle about every new Voronoi edge, and on the liver most of
// those questions come while the mesh is still coarse. Started instead from
// points about a final edge apart, it asks far fewer (on the liver, about a
// third less meshing time). The points are the solve's oriented points
// thinned greedily, in their own order, so that no two kept ones are
// nearer than `spacing`; each is then moved along its normal, up to `reach`
// either way, to where the function crosses zero (a point with no crossing
// there is left out). In Hilbert order, so that inserting them walks little.
// Deterministic: the same points give the same seeds.
inline std::vector<Point> mesher_seeds(const ZeroLevel& level,
                                       const std::vector<std::pair<Point, Vector>>& points,
                                       double spacing, double reach) {
  std::vector<Point> seeds;
  if (points.empty() || !(spacing > 0)) return seeds;
  CGAL::Bbox_3 box;
  for (const auto& point : points) box += point.first.bbox();
  // Cubes at least `spacing` across, so a kept point nearer than that lies
  // in one of the 27 cubes around; larger when that would make more than
  // 16 M of them (a long thin box, say).
  double cube = spacing;
  std::array<int64_t, 3> size;
  for (;; cube *= 2) {
    for (int axis = 0; axis < 3; ++axis)
      size[axis] = int64_t((box.max(axis) - box.min(axis)) / cube) + 1;
    if (double(size[0]) * double(size[1]) * double(size[2]) <= double(1 << 24)) break;
  }
  // Each cube's last kept point, and each kept point's previous one in its
  // cube (-1: none).
  std::vector<int32_t> last_in_cube(size_t(size[0] * size[1] * size[2]), -1);
  std::vector<int32_t> previous;
  std::vector<Point> kept;
  const double squared = spacing * spacing;
  for (const auto& [point, normal] : points) {
    std::array<int64_t, 3> at;
    for (int axis = 0; axis < 3; ++axis)
      at[axis] = std::min(int64_t((point[axis] - box.min(axis)) / cube), size[axis] - 1);
    bool near = false;
    for (int64_t z = std::max<int64_t>(at[2] - 1, 0); z <= std::min(at[2] + 1, size[2] - 1); ++z)
      for (int64_t y = std::max<int64_t>(at[1] - 1, 0); y <= std::min(at[1] + 1, size[1] - 1); ++y)
        for (int64_t x = std::max<int64_t>(at[0] - 1, 0); x <= std::min(at[0] + 1, size[0] - 1);
             ++x) {
          for (int32_t i = last_in_cube[size_t((z * size[1] + y) * size[0] + x)]; i >= 0 && !near;
               i = previous[size_t(i)])
            near = CGAL::squared_distance(point, kept[size_t(i)]) < squared;
        }
    if (near) continue;
    int32_t& last = last_in_cube[size_t((at[2] * size[1] + at[1]) * size[0] + at[0])];
    previous.push_back(last);
    last = int32_t(kept.size());
    kept.push_back(point);

    const double length = std::sqrt(normal.squared_length());
    if (!(length > 0)) continue;
    const Vector step = normal * (reach / length);
    const CGAL::Object hit = ZeroLevelOracle().intersect_3_object()(
        level, Kernel::Segment_3(point - step, point + step));
    if (const Point* on = CGAL::object_cast<Point>(&hit)) seeds.push_back(*on);
  }
  CGAL::hilbert_sort(seeds.begin(), seeds.end());
  return seeds;
}

}  // namespace labelmesh::surface::poisson
