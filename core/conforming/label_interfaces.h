// SPDX-License-Identifier: AGPL-3.0-or-later
// The interfaces between the labels of a volume as one smooth triangle
// surface in which touching labels share their triangles: a multi-label
// surface net. One point sits in each voxel cube (eight neighbouring voxel
// centres) whose corners hold more than one label (one per sheet where two
// labels a voxel apart cross it; InterfaceParams::split_sheets); each pair of
// face-neighbouring voxels with different labels gives the quad joining the
// points of the four cubes around the segment between them. With every point
// at its cube's centre that is exactly the voxels' staircase; the points are
// then smoothed, each held inside its cube, so the surface stays within one
// voxel of the labels' voxel boundary and cannot tear apart.
// Reference: S. Frisken, "SurfaceNets for Multi-Label Segmentations with
// Preservation of Sharp Boundaries", J. Computer Graphics Techniques 11(1), 2022.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/conforming/interface_surface.h"
#include "core/volume/label_volume.h"

namespace labelmesh::conforming {

struct InterfaceParams {
  // Taubin rounds (a shrinking step and an inflating one each): smooth the
  // staircase without shrinking convex organs the way plain averaging does.
  // Each step holds every point in its box (cube_fraction).
  int smoothing_rounds = 12;
  double shrink_step = 0.5;
  double inflate_step = -0.53;
  // How far a point may leave its cube's centre along each axis, as a
  // fraction of half the voxel: below 1, so points of neighbouring cubes
  // never meet.
  double cube_fraction = 0.9;
  // While and after smoothing, give each label back the volume smoothing
  // took, by moving the points between one pair of sides along their
  // normals: a thin label between others takes its volume from them, and
  // they from the outside.
  bool restore_volumes = false;
  // With restore_volumes, the smoothing also pauses this many times, evenly
  // spaced, for one round of giving volume back. A label three voxels
  // across shrinks around its cross-section under smoothing and, pressed
  // against its boxes, keeps their corners; given its volume back as it
  // goes, it stays off them and round.
  int volume_pauses = 0;
  // The box along each axis is this many times cube_fraction's (a grid cut
  // into thinner slices may let its points move as far as the thick ones').
  std::array<double, 3> box_scale{1, 1, 1};
  // On a grid cut into thinner slices (thick_slices.h): the axis cut, -1 for
  // none, and into how many parts. Between two drawn slices the thinner
  // slices' pixels are interpolated, not drawn: a point may move beyond its
  // box across the axis by up to this fraction of the voxel, more the
  // farther it lies from the nearest drawn slice (none on or near one, all
  // of it midway; point_boxes.h), so the interpolation's pixel steps do not
  // stay as ridges. Along the axis no point passes a drawn slice beyond its
  // cube's own box.
  int drawn_axis = -1;
  int drawn_parts = 1;
  double between_drawn_widening = 0;
  // After smoothing, move the points of quads whose triangles have an angle
  // below this many degrees inside their boxes where that widens the angle
  // (widen_small_angles.h); 0: leave them. Not with subdivide_thick_quads.
  // Across the surface a point moves about a quarter voxel where the angle
  // is below widen_far_below_deg, about a sixteenth where it lies between
  // the two (AngleLimits).
  double widen_angles_below_deg = 0;
  double widen_far_below_deg = 20;
  // Cut each quad on a grid with thicker slices into near-square ones (for
  // tetrahedra); surfaces keep one quad per voxel face.
  bool subdivide_thick_quads = true;
  // A point per sheet through a cube (cube_sheets.h), so that two faces a
  // voxel apart can part; not on a grid cut into thinner slices.
  bool split_sheets = false;
  // Smooth the rim of each flat cap on the volume's edge as a curve
  // (cap_rims.h), not held to the last slice's pixel steps by the cap.
  bool follow_cap_rims = false;
  // With split_sheets: voxels (linear indices into the volume, x fastest,
  // sorted) whose cubes keep one point, where parted faces crossed.
  std::vector<uint64_t> joined_voxels;
};

struct InterfaceFigures {
  size_t points = 0;
  size_t triangles = 0;
  // Points where three or more labels meet; of those, the ones smoothed
  // along their junction curve only (next to a small label). Fixed points:
  // where such curves meet or end, and every point next to a label of a few
  // voxels, which keeps its voxels' shape.
  size_t junction_points = 0;
  size_t curve_points = 0;
  size_t fixed_points = 0;
  // Points on the rim of a cap on the volume's edge, smoothed along the rim
  // only (cap_rims.h).
  size_t rim_points = 0;
  // The farthest any point lies from its staircase position, mm: the surface
  // is within this distance of the voxel boundary (both share triangles).
  double max_offset_mm = 0;
  // Points slid along the surface to widen small angles.
  size_t widened_points = 0;
  double seconds = 0;
};

// Builds the interface surface of `labels` in `volume` (all non-zero labels
// when empty). Labels outside the list count as the outside. Triangles are
// split from their quads along the diagonal that gives the larger smallest
// angle.
InterfaceSurface label_interfaces(const volume::LabelVolume& volume,
                                  const std::vector<int32_t>& labels, const InterfaceParams& params,
                                  InterfaceFigures& figures);

// Moves `points` (indices into surface.points) back to their staircase
// positions: what the mesher does where smoothing made two patches cross.
void restore_staircase(InterfaceSurface& surface, const std::vector<uint32_t>& points);

}  // namespace labelmesh::conforming
