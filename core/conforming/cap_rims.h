// SPDX-License-Identifier: AGPL-3.0-or-later
// The rims of the flat caps where a label is cut by the volume's edge,
// smoothed as curves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/conforming/constrained_smoothing.h"
#include "core/conforming/point_boxes.h"

namespace labelmesh::conforming {

// A cap's points stay on the edge's plane (PointBoxes::pinned); its rim is
// where the cap meets the label's wall inside the volume. Averaged over all
// four neighbours, a rim point is held to the staircase by the cap's grid
// beside it, and the rim keeps the pixel steps of the last slice's contour.
// Each rim point between two labels with exactly two neighbours on its rim
// (pinned to the same plane) instead averages over those two, as a junction
// curve held sharp does: the edge of the volume is a third side there. Its
// box still holds it, and the widening of thin triangles still moves it
// over the surface. Returns how many points now follow their rim.
size_t follow_cap_rims(const PointBoxes& boxes, const std::vector<uint8_t>& label_count,
                       Stencil& stencil);

}  // namespace labelmesh::conforming
