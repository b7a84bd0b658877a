// SPDX-License-Identifier: AGPL-3.0-or-later
// Smoothing a surface net inside the voxels' boxes leaves a few thin
// triangles: two points pressed into facing corners of their boxes, or three
// nearly in a line. Each point of such a quad slides towards the middle of
// its neighbours in the surface's tangent plane (which keeps the shape to
// first order), or where that is not enough moves a little along a voxel
// axis (which changes it), whichever widens the smallest angle around it
// most. It never leaves its box (point_boxes.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/conforming/interface_surface.h"
#include "core/conforming/point_boxes.h"
#include "core/surface/crossing_triangles.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {

// The cosine of the smallest angle of quad (a, b, c, d) split along the
// diagonal that gives the larger smallest angle, and that diagonal.
struct QuadSplit {
  double cosine = 1;
  bool along_02 = true;  // triangles (0, 1, 2), (0, 2, 3); else (0, 1, 3), (1, 2, 3)
};
QuadSplit best_quad_split(const std::array<uint32_t, 4>& quad,
                          const std::vector<geometry::Vec3>& points);

// How a point may slide: not at all; within the surface's tangent plane
// (a point smoothed over all its neighbours, where three labels meet too);
// or, on a junction curve held sharp, parallel to the line through its two
// neighbours there.
struct Slide {
  enum class Kind : uint8_t { kFixed, kSurface, kCurve };
  Kind kind = Kind::kFixed;
  std::array<uint32_t, 2> curve{0, 0};  // kCurve: the neighbours on the curve
};

// What the widening did.
struct WidenedAngles {
  size_t points_moved = 0;
};

// Which quads are widened, and how far their points may move across the
// surface, which changes the shape inside the box: a whole step where the
// angle is far below the limit, a short one near it (docs/design-notes.md,
// "Thin triangles on the net").
struct AngleLimits {
  // Degrees: quads whose best split has an angle below this are widened.
  double below_deg = 20;
  // Degrees: below this a point may move the whole `across` step; from here
  // up to below_deg, short_fraction of it. At or above below_deg: the whole
  // step throughout.
  double far_below_deg = 20;
  // The short step as a fraction of the whole one.
  double short_fraction = 0.25;
};

// Passes over the thin quads' points: a point that moves changes its
// neighbours' quads too, and later passes visit only those. Beyond six,
// passes leave hardly fewer thin triangles (docs/design-notes.md).
inline constexpr int kWideningPasses = 6;

// Moves the points of quads whose best split has an angle below
// limits.below_deg, each held in its box around its `centre`: along the
// surface first, and where that is not enough, along a voxel axis by
// `across` (or the short part of it; AngleLimits). Positions, boxes and
// moves are in mm along the voxel axes.
// `quad_sides` orient the quads (a quad's normal points from its lower side
// label to its higher one, as for every quad between the same two labels).
// A point moves only when the smallest angle of its quads grows, so the
// smallest angle over all quads never shrinks.
WidenedAngles widen_small_angles(const std::vector<std::array<uint32_t, 4>>& quads,
                                 const std::vector<std::array<int32_t, 2>>& quad_sides,
                                 const std::vector<Slide>& slides,
                                 const std::vector<geometry::Vec3>& centre, const PointBoxes& boxes,
                                 const geometry::Vec3& across, const AngleLimits& limits,
                                 std::vector<geometry::Vec3>& points);

// A move in a crossing pair goes back by half of what is left of it this
// many times, and then wholly: most crossings at the rims of thin sheets
// clear after a part of the move, which keeps part of its wider angle.
inline constexpr int kHalvings = 3;

// Takes back half of what is left of the slide of each slid point of the
// `crossing` triangle pairs (the surface's `widened` list), or all of it
// after kHalvings halvings, putting the point where smoothing left it; a
// point half way may lie outside a box that widens between drawn slices
// (point_boxes.h: such boxes are not convex), never farther from its
// staircase place than the wider of the two ends allows;
// splits each of their quads (triangles 2q and 2q + 1) again along the
// diagonal that gives the larger smallest angle, and returns the triangles
// of those quads.
std::vector<uint32_t> take_back_crossing_slides(InterfaceSurface& surface,
                                                const surface::TrianglePairs& crossing);

// The crossing triangle pairs of `surface` (surface/crossing_triangles.h)
// once no slid point is left in a crossing pair: the pairs around the quads
// taken back are found again until none holds a slid point.
surface::TrianglePairs crossings_after_taking_back_slides(InterfaceSurface& surface);

}  // namespace labelmesh::conforming
