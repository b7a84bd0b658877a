// SPDX-License-Identifier: AGPL-3.0-or-later
// Planes of a label volume that repeat the plane before them. A segmentation
// drawn on every third slice and resampled to thinner slices by nearest
// neighbour holds runs of three equal slices: its surfaces step three voxels
// at a time, and no smooth surface can follow it closer than such a step
// allows (the liver file: 2 mm steps on 0.67 mm slices).
#pragma once

#include <array>
#include <vector>

#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

// Per voxel axis, changed[p] for each plane p: whether any voxel of plane p
// differs from its neighbour in plane p - 1 (false for plane 0). All false
// for a voxel type labelmesh does not keep in memory.
std::array<std::vector<bool>, 3> find_plane_changes(const LabelVolume& volume);

// Per voxel axis, the length L >= 2 shared by every run of equal consecutive
// planes across the box that holds the labels, when at least two whole runs
// lie inside it; the box's first and last runs may be shorter (the
// resampling may have cut them). 1 for any other axis: planes that change
// from one to the next, runs of mixed lengths, or too few runs to tell.
std::array<int, 3> find_repeated_planes(const LabelVolume& volume,
                                        const VolumeStatistics& statistics);

}  // namespace labelmesh::volume
