// SPDX-License-Identifier: AGPL-3.0-or-later
// Taubin smoothing of the surface net's points, each step holding every
// point in a box around its staircase position (Frisken's constrained
// smoothing).
#pragma once

#include <cstdint>
#include <vector>

#include "core/conforming/label_interfaces.h"
#include "core/conforming/point_boxes.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {

// Neighbours each point averages over: every neighbour on a patch between
// two labels; on a junction curve held sharp, only its two neighbours on the
// curve; on the rim of a cap on the volume's edge, only its two neighbours on
// the rim (cap_rims.h). Points where such curves meet or end, and points
// next to a label of a few voxels, have none and stay fixed.
struct Stencil {
  std::vector<uint32_t> start;  // CSR offsets, one past the last point
  std::vector<uint32_t> neighbours;
  // Per point: smoothed along a junction curve (its two neighbours), which
  // the angle widening slides it along. Rim points are not marked: they
  // slide over the surface.
  std::vector<bool> along_curve;
};

// `rounds` rounds of params' shrink_step and inflate_step, each point
// moving towards the mean of its stencil neighbours and held in its box
// around centre[p]. Points without neighbours stay exactly where they
// are. Two threads share large nets; the result is the same as one thread's.
void smooth_in_boxes(const Stencil& stencil, const std::vector<geometry::Vec3>& centre,
                     const PointBoxes& boxes, const InterfaceParams& params, int rounds,
                     std::vector<geometry::Vec3>& points);

}  // namespace labelmesh::conforming
