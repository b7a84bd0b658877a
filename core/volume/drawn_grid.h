// SPDX-License-Identifier: AGPL-3.0-or-later
// The grid a segmentation was drawn on, when the file holds it resampled by
// nearest neighbour to finer pixels: a 3 mm segmentation stored on a CT's
// 0.98 mm grid holds blocks of 3 or 4 equal pixels along x and y. Faithful
// to those pixels a surface must step with the blocks; on the grid the
// labels were drawn on the same labels allow a smooth one.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// One voxel axis of the drawn grid, in the file's voxel index: drawn voxel c
// spans [first_boundary + c pitch, first_boundary + (c + 1) pitch] (the first
// holds the file's first voxel centre, 0, the last its last) and takes
// the label of the file's voxel nearest its centre.
struct DrawnAxis {
  double pitch = 1;  // file voxels per drawn voxel
  double first_boundary = -0.5;
  int64_t count = 0;  // drawn voxels that overlap the file's extent
};

// The drawn grid along each of the file's voxel axes.
struct DrawnGrid {
  std::array<DrawnAxis, 3> axes;
  // Blocks along two axes or more: the whole image was resampled. Planes
  // repeated along one axis alone are slices drawn apart, which the delivery
  // tolerance allows for (repeated_planes.h) and the meshers keep.
  bool resampled() const;
};

// An axis counts as drawn coarser when every plane where a label changes
// (in any layer) lies within half a voxel of one lattice of pitch 1.5 to 8
// (the rounding of nearest-neighbour resampling), with at least
// kMinDrawnChanges such planes and at most a quarter of the gaps between
// them longer than one step (under a pitch of 2: at least 32 planes, and
// none of the lattice's boundaries between them without a change); else
// its pitch is 1. The pitch is the one whose
// offsets span the least (a minimax line fit).
inline constexpr int kMinDrawnChanges = 8;
DrawnGrid find_drawn_grid(const LabelVolume& volume);

// A grid of drawn voxels over the file's: its geometry (the same directions,
// spacing times pitch, the origin at drawn voxel 0's centre) and, per axis,
// the file voxel nearest each drawn voxel's centre. Nearest-neighbour
// resampling onto any such lattice reads its labels there.
struct DrawnSampling {
  ImageGeometry geometry;
  std::array<std::vector<int64_t>, 3> source;
};
DrawnSampling drawn_sampling(const ImageGeometry& file, const std::array<DrawnAxis, 3>& axes);

// The volume on `grid` (every layer), in the same physical space: spacing
// times pitch, the origin at the first drawn voxel's centre, int32 voxels.
// Errors: RESOURCE_EXHAUSTED when it cannot be allocated.
absl::StatusOr<LabelVolume> resample_to_drawn_grid(const LabelVolume& volume,
                                                   const DrawnGrid& grid);

}  // namespace labelmesh::volume
