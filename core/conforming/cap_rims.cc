// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/cap_rims.h"

#include <bit>

namespace labelmesh::conforming {

size_t follow_cap_rims(const PointBoxes& boxes, const std::vector<uint8_t>& label_count,
                       Stencil& stencil) {
  if (boxes.pinned.empty() || stencil.start.empty()) return 0;
  const size_t n = stencil.start.size() - 1;
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
  const auto on_rim_with = [&](size_t p, uint32_t q) { return rim[q] && plane(q) == plane(p); };
  // Compacted in place: a point's new list never ends after its old one.
  size_t following = 0;
  uint32_t write = 0;
  for (size_t p = 0; p < n; ++p) {
    const uint32_t first = stencil.start[p], last = stencil.start[p + 1];
    stencil.start[p] = write;
    size_t on_rim = 0;
    if (rim[p])
      for (uint32_t i = first; i < last; ++i) on_rim += on_rim_with(p, stencil.neighbours[i]);
    const bool follows = on_rim == 2;
    following += follows;
    for (uint32_t i = first; i < last; ++i) {
      const uint32_t q = stencil.neighbours[i];
      if (!follows || on_rim_with(p, q)) stencil.neighbours[write++] = q;
    }
  }
  stencil.start[n] = write;
  stencil.neighbours.resize(write);
  return following;
}

}  // namespace labelmesh::conforming
