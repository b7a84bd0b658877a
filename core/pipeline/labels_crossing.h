// SPDX-License-Identifier: AGPL-3.0-or-later
// Labels cut from the shared surface net never pass through each other: they
// share their interfaces. A label delivered another way (the lighter net,
// Poisson, the meshed mask) is made apart from its neighbours, and its
// surface can enter theirs, across the gap between the labels or where they
// touch, which no label's own check sees. This finds where it does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/pipeline/mesh_result.h"

namespace labelmesh {

// A delivered surface made apart from the shared net that crosses the
// delivered surface of `other`.
struct LabelsCrossing {
  int32_t label = 0;
  int32_t other = 0;
  size_t triangle_pairs = 0;  // triangles of `label` and of `other` that cross
};

// For every delivered surface (is_output) of `surfaces` whose stage is not
// "net", the other delivered surfaces it crosses: in the order of
// `surfaces`, each one's crossings by the other label's number. Two labels
// made apart that cross are listed once, under the first. A surface wholly
// inside another crosses none of its triangles and is not seen. Surfaces
// that are all "net" give none. With `layer_of` (label, layer pairs; a
// label not listed is in layer 0), only labels of one layer are tested
// against each other: a layer's segments overlap some of the other layers'
// in the voxels, and so may their surfaces. Two segments of different
// layers that do not overlap are not tested either.
std::vector<LabelsCrossing> labels_crossing(
    const std::vector<SurfaceResult>& surfaces,
    const std::vector<std::pair<int32_t, size_t>>& layer_of = {});

}  // namespace labelmesh
