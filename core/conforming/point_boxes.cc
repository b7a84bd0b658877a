// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/point_boxes.h"

namespace labelmesh::conforming {

using geometry::Vec3;

Vec3 PointBoxes::hold(size_t point, const Vec3& centre, Vec3 p) const {
  // Pinned axes first: the widening follows from where the point is.
  const uint8_t axes = pinned_axes(point);
  for (int k = 0; k < 3; ++k)
    if (axes & (1u << k)) p[k] = centre[k];
  Vec3 width = half;
  if (drawn_axis >= 0) {
    // Along the drawn axis first: the width across follows from there.
    const int a = drawn_axis;
    const auto [low, high] = along_drawn(centre[a]);
    p[a] = std::clamp(p[a], low, high);
    if (widens(point)) {
      const double between = BetweenDrawn<double>(drawn_first, drawn_spacing)(p[a]);
      for (int k = 0; k < 3; ++k) width[k] += between * widening[k];
    }
  }
  for (int k = 0; k < 3; ++k) {
    p[k] = std::clamp(p[k], std::max(centre[k] - width[k], edge_low[k]),
                      std::min(centre[k] + width[k], edge_high[k]));
  }
  return p;
}

void hold_at_edges(const std::vector<Vec3>& centre, const volume::ImageGeometry& geometry,
                   PointBoxes& boxes) {
  for (int k = 0; k < 3; ++k) {
    boxes.edge_low[k] = -0.5 * geometry.spacing[k];
    boxes.edge_high[k] = (double(geometry.dims[k]) - 0.5) * geometry.spacing[k];
  }
  std::vector<uint8_t>& pinned = boxes.pinned;
  pinned.assign(centre.size(), 0);
  bool any = false;
  for (size_t p = 0; p < centre.size(); ++p) {
    for (int k = 0; k < 3; ++k) {
      // The cube's lower voxel index along k: -1 or the last voxel reach past
      // the edge.
      const double low = centre[p][k] / geometry.spacing[k] - 0.5;
      if (low < -0.5 || low > double(geometry.dims[k]) - 1.5) {
        pinned[p] |= static_cast<uint8_t>(1u << k);
        any = true;
      }
    }
  }
  if (!any) std::vector<uint8_t>().swap(pinned);
}

PointBoxes point_boxes(const volume::ImageGeometry& geometry, const InterfaceParams& params) {
  const auto& spacing = geometry.spacing;
  PointBoxes boxes;
  for (int k = 0; k < 3; ++k)
    boxes.half[k] = 0.5 * params.cube_fraction * spacing[k] * params.box_scale[k];
  const int a = params.drawn_axis;
  if (a < 0 || params.drawn_parts < 2) return boxes;
  boxes.drawn_axis = a;
  boxes.drawn_spacing = spacing[a] * params.drawn_parts;
  // Thin slice j's centre lies at j times its spacing; drawn slice k's at
  // thin slice (k + 1/2) parts - 1/2.
  boxes.drawn_first = 0.5 * (boxes.drawn_spacing - spacing[a]);
  boxes.thin_half = 0.5 * params.cube_fraction * spacing[a];
  for (int k = 0; k < 3; ++k)
    if (k != a) boxes.widening[k] = std::max(0.0, params.between_drawn_widening) * spacing[k];
  return boxes;
}

}  // namespace labelmesh::conforming
