// SPDX-License-Identifier: AGPL-3.0-or-later
// One label's closed surface cut out of the labels' shared interface surface
// (label_interfaces.h): every triangle with the label on one side, wound
// outward. Touching labels therefore get the same triangles where they meet.
// Where the label's voxels touch each other only along an edge or at a
// corner, the point there is split into one copy per voxel and each copy is
// nudged towards its own voxel, so the surface stays 2-manifold.
#pragma once

#include <cstdint>
#include <vector>

#include "core/conforming/interface_surface.h"
#include "core/header/image_geometry.h"
#include "core/surface/crossing_triangles.h"
#include "core/surface/triangle_mesh.h"

namespace labelmesh::conforming {

struct NetLabelSurface {
  // LPS, mm; outward.
  surface::TriangleMesh mesh;
  // The same triangles with every point at its staircase position: the
  // exact boundary of the label's voxels.
  surface::TriangleMesh staircase;
  // Copies made where the label's voxels touch only along an edge or at a
  // corner.
  uint32_t split_points = 0;
  // Per triangle: the net triangle it is.
  std::vector<uint32_t> net_triangles;
  // The triangles with a split copy as a corner, sorted: the only ones not
  // where the net has them.
  std::vector<uint32_t> moved_triangles;
  // Crossing pairs of triangles with one of moved_triangles among them,
  // left after the copies moved farther apart (SplitCrossings::kPart).
  uint64_t split_crossings = 0;
};

// How far a split copy moves from the shared point towards the centre of its
// own voxels, as a fraction of the way: enough to part the copies, little
// enough that a label of a few voxels touching along edges keeps its
// volume (a tenth took 11 % of four voxels in a row).
inline constexpr double kSplitNudge = 0.05;
// Where two copies' triangles pass through each other (smoothing can leave
// two sheets that touch along an edge pinched across it), the copies'
// fraction is doubled, at most this many times: at most 0.4 of the way.
inline constexpr int kSplitNudgeDoublings = 3;
static_assert(kSplitNudge * (1 << kSplitNudgeDoublings) < 0.5);

// Whether net_label_surface parts split copies whose triangles cross and
// counts the pairs left, or leaves them (a cut read only for its staircase).
enum class SplitCrossings { kPart, kLeave };

// The surface of `label` in `net` (empty when no triangle bounds it).
// `geometry` is the volume the net was built from.
NetLabelSurface net_label_surface(const InterfaceSurface& net, int32_t label,
                                  const volume::ImageGeometry& geometry,
                                  SplitCrossings split_crossings = SplitCrossings::kPart);

// Crossing triangle pairs of `cut`, the surface of `label` in `net`, given
// the net's own crossing pairs (surface::crossing_triangles): the net's pairs
// of two triangles of the label where it keeps the net's triangles, and
// those around its split copies (NetLabelSurface::split_crossings; the cut
// made with SplitCrossings::kPart). The same count as
// surface::count_self_intersections on cut.mesh, for a fraction of the work
// when the net's pairs serve all its labels.
uint64_t net_label_self_intersections(const InterfaceSurface& net,
                                      const surface::TrianglePairs& net_crossings,
                                      const NetLabelSurface& cut, int32_t label);

}  // namespace labelmesh::conforming
