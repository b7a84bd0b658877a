// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/cap_rims.h"

#include <bit>

namespace labelmesh::conforming {

size_t follow_cap_rims(const PointBoxes& boxes, const std::vector<uint8_t>& label_count,
                       Stencil& stencil) {
  const size_t n = stencil.start.size() - 1;
  if (boxes.pinned.empty()) return 0;
  // The one plane a point is pinned to, 0 for none or a corner of the
  // volume's box (pinned to two planes or three).
  const auto plane = [&](size_t p) -> uint8_t {
    const uint8_t axes = boxes.pinned_axes(p);
    return std::popcount(axes) == 1 ? axes : 0;
  };
  // Rim points: between two labels, on one plane, with a neighbour off it.
  std::vector<bool> rim(n, false);
  for (size_t p = 0; p < n; ++p) {
    if (plane(p) == 0 || label_count[p] > 2 || stencil.along_curve[p]) continue;
    for (uint32_t i = stencil.start[p]; i < stencil.start[p + 1]; ++i) {
      if ((boxes.pinned_axes(stencil.neighbours[i]) & plane(p)) == 0) {
        rim[p] = true;
        break;
      }
    }
  }
  Stencil followed;
  followed.start.assign(n + 1, 0);
  followed.neighbours.reserve(stencil.neighbours.size());
  followed.along_curve = stencil.along_curve;
  size_t following = 0;
  for (size_t p = 0; p < n; ++p) {
    followed.start[p] = static_cast<uint32_t>(followed.neighbours.size());
    const uint32_t first = stencil.start[p], last = stencil.start[p + 1];
    size_t on_rim = 0;
    if (rim[p]) {
      for (uint32_t i = first; i < last; ++i) {
        const uint32_t q = stencil.neighbours[i];
        if (rim[q] && plane(q) == plane(p)) ++on_rim;
      }
    }
    if (on_rim == 2) {
      for (uint32_t i = first; i < last; ++i) {
        const uint32_t q = stencil.neighbours[i];
        if (rim[q] && plane(q) == plane(p)) followed.neighbours.push_back(q);
      }
      ++following;
    } else {
      followed.neighbours.insert(followed.neighbours.end(), stencil.neighbours.begin() + first,
                                 stencil.neighbours.begin() + last);
    }
  }
  followed.start[n] = static_cast<uint32_t>(followed.neighbours.size());
  stencil = std::move(followed);
  return following;
}

}  // namespace labelmesh::conforming
