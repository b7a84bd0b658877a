// SPDX-License-Identifier: AGPL-3.0-or-later
// Voxel counts and index bounding boxes per label, in one pass over a volume.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/volume/label_volume.h"

namespace labelmesh::volume {

struct LabelStatistics {
  int32_t label = 0;
  uint64_t voxels = 0;
  // Inclusive voxel-index bounds: {min_i, min_j, min_k}, {max_i, max_j, max_k}.
  std::array<int64_t, 3> min_index{0, 0, 0};
  std::array<int64_t, 3> max_index{0, 0, 0};
};

struct VolumeStatistics {
  // Every label present except 0, ascending.
  std::vector<LabelStatistics> labels;
  uint64_t background_voxels = 0;

  const LabelStatistics* find(int32_t label) const;
};

// Counts every label of `volume`. Linear in the voxel count; labels of 8- and
// 16-bit volumes are tallied in a direct table, 32-bit labels in a hash map.
VolumeStatistics compute_label_statistics(const LabelVolume& volume);

}  // namespace labelmesh::volume
