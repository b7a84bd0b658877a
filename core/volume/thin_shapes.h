// SPDX-License-Identifier: AGPL-3.0-or-later
// A multi-label phantom of the thin and small structures AI segmentations are
// full of (ribs, vessels, cortex, stray voxels), each a label of its own, for
// the never-crash and faithfulness tests of the surface pipeline.
#pragma once

#include <array>
#include <string_view>
#include <vector>

#include "core/volume/phantom.h"

namespace labelmesh::volume {

// What each label of the thin-shapes phantom is. Sizes are in units of the
// grid's largest spacing ("voxels"), so the shapes are as thin on a 3 mm grid
// as on a 1 mm one.
struct ThinShape {
  int32_t label = 0;
  std::string_view name;
};

// Labels 1-11: straight tubes 1, 2 and 4 voxels across; a torus 3 across (a
// rib); a helix 3 across (a vessel); an arc-shaped tube 2 across; a flat
// plate 1 voxel thick and a curved plate 2 thick; one voxel; two voxels; a
// tube 3 across that runs out of the volume's edge.
const std::vector<ThinShape>& thin_shapes();

// The phantom on a grid of `spacing` mm per voxel axis (identity direction).
// Truth is given for the shapes with exact volumes (tubes as capsules, the
// torus, the flat plate, the voxels).
Phantom make_thin_shapes(const std::array<double, 3>& spacing);

}  // namespace labelmesh::volume
