// SPDX-License-Identifier: AGPL-3.0-or-later
// Which labels of a volume touch: their voxels share a face. Meshed one by
// one (tetrahedra, mixed elements), two touching labels get separate meshes
// that overlap along their interface instead of sharing its nodes.
#pragma once

#include <cstdint>
#include <vector>

#include "core/volume/label_volume.h"

namespace labelmesh::volume {

struct TouchingLabels {
  int32_t first = 0;  // the smaller label
  int32_t second = 0;
  // Voxel faces between them.
  uint64_t faces = 0;
};

// The pairs of `labels` whose voxels share a face in `volume`, sorted by
// label; every label when `labels` is empty. Background (0) never counts.
std::vector<TouchingLabels> touching_labels(const LabelVolume& volume,
                                            const std::vector<int32_t>& labels);

}  // namespace labelmesh::volume
