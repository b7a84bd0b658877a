// SPDX-License-Identifier: AGPL-3.0-or-later
// The rims of the flat caps where a label is cut by the volume's edge,
// smoothed as curves instead of held to the last slice's pixel steps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/conforming/constrained_smoothing.h"
#include "core/conforming/point_boxes.h"

namespace labelmesh::conforming {

// Rewrites `stencil` so that each cap rim point averages over its two rim
// neighbours only.
//
// A cap's points stay on the edge's plane (PointBoxes::pinned, which
// hold_at_edges must have filled); its rim is where the cap meets the
// label's wall inside the volume. Averaged over all its neighbours, a rim
// point is held to the staircase by the cap's grid beside it, and the rim
// keeps the pixel steps of the last slice's contour. A rim point here is a
// point between two labels (`label_count`, per point), pinned to one plane
// only, with a stencil neighbour off that plane; one with exactly two rim
// neighbours on the same plane averages over those two, as a junction curve
// held sharp does (the edge of the volume is a third side there). Others
// keep their neighbours, as do points where three labels meet. Its box
// still holds it, and the angle widening still slides it over the surface
// (along_curve stays false). Returns how many points now follow their rim.
size_t follow_cap_rims(const PointBoxes& boxes, const std::vector<uint8_t>& label_count,
                       Stencil& stencil);

}  // namespace labelmesh::conforming
