// SPDX-License-Identifier: AGPL-3.0-or-later
// Crossings of faces parted across a one-voxel gap (cube_sheets.h): two
// labels' faces in the same boxes may pass through each other after
// smoothing, which neither label's own check sees. These helpers find such
// pairs and the voxels around them, whose cubes can then keep one point.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/conforming/interface_surface.h"
#include "core/surface/crossing_triangles.h"

namespace labelmesh::conforming {

// Whether triangles a and b of `net` share no label but the outside.
bool shares_only_outside(const InterfaceSurface& net, uint32_t a, uint32_t b);

// The voxels on both sides of each triangle of the pairs among `crossings`
// that share only the outside, and those within `reach` voxels of them
// (a cube of side 2 reach + 1), as sorted linear indices into the volume
// of `dims` (x fastest).
std::vector<uint64_t> voxels_near_parted_crossings(const InterfaceSurface& net,
                                                   const surface::TrianglePairs& crossings,
                                                   const std::array<int64_t, 3>& dims, int reach);

}  // namespace labelmesh::conforming
