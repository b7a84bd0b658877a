// SPDX-License-Identifier: AGPL-3.0-or-later
// The boxes the surface net's points are held in while they are smoothed
// and moved: around each point's staircase position, wider between drawn
// slices on a grid cut into thinner ones.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/conforming/label_interfaces.h"
#include "core/util/vec3.h"
#include "core/volume/label_volume.h"

namespace labelmesh::conforming {

// Where each point may lie: within `half` of its centre along each axis,
// and across a drawn axis up to `widening` more, growing with the point's
// distance from the nearest drawn slice (BetweenDrawn below;
// InterfaceParams::between_drawn_widening). Along a drawn axis a point never
// passes a drawn slice beyond its cube's own box (along_drawn).
struct PointBoxes {
  geometry::Vec3 half{0, 0, 0};
  int drawn_axis = -1;               // -1: every box is fixed
  double drawn_spacing = 0;          // mm between drawn slices
  double drawn_first = 0;            // a drawn slice's place along the axis, mm
  double thin_half = 0;              // a thin cube's own half box along it, mm
  geometry::Vec3 widening{0, 0, 0};  // mm midway between drawn slices; 0 along the axis
  // Points whose boxes never widen (where three labels or more meet): a
  // junction curve held to its pixels keeps its points apart.
  std::vector<bool> narrow;
  // Per point, the axes (bit k for axis k) along which it stays on its
  // centre: points whose cube reaches past the volume's edge, so that a
  // label cut by the edge ends in a flat cap on it. Empty: none.
  std::vector<uint8_t> pinned;
  // The volume's edges along each axis (mm, as the centres): no point goes
  // past them, whatever its box.
  geometry::Vec3 edge_low{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  geometry::Vec3 edge_high{HUGE_VAL, HUGE_VAL, HUGE_VAL};

  // Along the drawn axis, where a point whose cube's centre lies at
  // `centre` (mm) may go: within its box, and never past a drawn slice
  // beyond the cube's own box. Carried onto a drawn slice from a thin slice
  // beside it, a point would bring that slice's contour past the drawn
  // voxel centres there. Only with drawn_axis >= 0.
  template <typename Real>
  std::array<Real, 2> along_drawn(Real centre) const {
    const auto spacing = static_cast<Real>(drawn_spacing);
    const auto first = static_cast<Real>(drawn_first);
    const auto own = static_cast<Real>(thin_half);
    const auto box = static_cast<Real>(half[drawn_axis]);
    const Real below = first + std::floor((centre - own - first) / spacing) * spacing;
    const Real above = first + std::ceil((centre + own - first) / spacing) * spacing;
    return {std::max(centre - box, below), std::min(centre + box, above)};
  }

  bool widens(size_t point) const {
    return drawn_axis >= 0 && (point >= narrow.size() || !narrow[point]);
  }
  uint8_t pinned_axes(size_t point) const { return point < pinned.size() ? pinned[point] : 0; }
  // Point `point`, at p, held in its box around `centre`.
  geometry::Vec3 hold(size_t point, const geometry::Vec3& centre, geometry::Vec3 p) const;
};

// Each point's box on `geometry` (cube_fraction of half a voxel along each
// axis, times box_scale). When params name a drawn axis cut into two parts
// or more, no point passes a drawn slice beyond its cube's own box, and
// boxes widen across between drawn slices (when between_drawn_widening is
// above 0). `narrow` and `pinned` are left empty.
PointBoxes point_boxes(const volume::ImageGeometry& geometry, const InterfaceParams& params);

// Pins the points at `centre` (cube centres in mm from voxel (0, 0, 0), as
// the net's) whose cube reaches past the first or last voxel along an axis
// of `geometry` to the edge there, and keeps every point within the edges.
void hold_at_edges(const std::vector<geometry::Vec3>& centre, const volume::ImageGeometry& geometry,
                   PointBoxes& boxes);

// Within this fraction of the way from a drawn slice to the middle between
// two, boxes stay as narrow as on the drawn slice: a triangle reaching the
// drawn slice from a point just off it would otherwise cross the drawn
// voxel centres there.
inline constexpr double kNarrowNearDrawn = 0.2;

// How far between two drawn slices (the first at `first`, `spacing` apart) a
// place lies along their axis, for the widening: 0 on or near one
// (kNarrowNearDrawn), 1 midway. The reciprocals are taken once: the net's
// smoothing asks at every point and step.
template <typename Real>
class BetweenDrawn {
 public:
  BetweenDrawn(double first, double spacing)
      : first_(static_cast<Real>(first)),
        spacing_(static_cast<Real>(spacing)),
        per_spacing_(spacing > 0 ? static_cast<Real>(1 / spacing) : Real{0}),
        per_half_spacing_(spacing > 0 ? static_cast<Real>(2 / spacing) : Real{0}) {}

  Real operator()(Real place) const {
    const Real offset = place - first_;
    const Real into = offset - std::floor(offset * per_spacing_) * spacing_;
    const Real between = std::min(into, spacing_ - into) * per_half_spacing_;
    return std::clamp((between - kNarrow) * kPerWideningSpan, Real{0}, Real{1});
  }

 private:
  static constexpr auto kNarrow = static_cast<Real>(kNarrowNearDrawn);
  // Over the part of the way to the middle where boxes widen.
  static constexpr auto kPerWideningSpan = static_cast<Real>(1 / (1 - kNarrowNearDrawn));
  Real first_, spacing_, per_spacing_, per_half_spacing_;
};

}  // namespace labelmesh::conforming
