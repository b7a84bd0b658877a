// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/point_boxes.h"

namespace labelmesh::conforming {

using geometry::Vec3;

Vec3 PointBoxes::hold(size_t point, const Vec3& centre, Vec3 p) const {
  Vec3 width = half;
  if (widens(point)) {
    const int a = drawn_axis;
    p[a] = std::clamp(p[a], centre[a] - half[a], centre[a] + half[a]);
    const double between = between_drawn(p[a], drawn_first, drawn_spacing);
    for (int k = 0; k < 3; ++k) width[k] += between * widening[k];
  }
  for (int k = 0; k < 3; ++k) p[k] = std::clamp(p[k], centre[k] - width[k], centre[k] + width[k]);
  return p;
}

}  // namespace labelmesh::conforming
