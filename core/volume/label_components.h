// SPDX-License-Identifier: AGPL-3.0-or-later
// Connected pieces of one label (26-connected voxels), so that each piece can
// be reconstructed on its own and tiny islands can be dropped.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include "absl/status/statusor.h"
#include "core/util/run_context.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh::volume {

struct LabelComponent {
  // 1-based id, as stored in LabelComponents::ids.
  int32_t id = 0;
  uint64_t voxels = 0;
  // Inclusive voxel-index bounds, as in LabelStatistics.
  std::array<int64_t, 3> min_index{0, 0, 0};
  std::array<int64_t, 3> max_index{0, 0, 0};
};

struct ComponentOptions {
  // Remove strands one voxel thick (voxels with at most one face neighbour,
  // repeatedly) before labelling.
  bool prune_strands = true;
  // Fill cavities (background pockets the label encloses, 6-connected) of
  // fewer voxels than this before labelling; 0 fills none.
  uint64_t fill_cavities_below = 0;
};

struct LabelComponents {
  // int32 image in the volume's index space, covering the label's bounding box
  // plus one voxel all round: a voxel holds its component's id, 0 elsewhere.
  vtkSmartPointer<vtkImageData> ids;
  // In order of first voxel in memory order (i fastest), which is stable for a
  // given volume: ids and order never depend on timing or threads.
  std::vector<LabelComponent> components;
  // Voxels removed as one-voxel strands; in no component.
  uint64_t pruned_voxels = 0;
  // Cavities filled (fill_cavities_below), and their voxels, now in the label.
  uint32_t filled_cavities = 0;
  uint64_t filled_voxels = 0;
};

// Labels the 26-connected components of `label`, after pruning one-voxel
// strands if asked. Voxels touching by a corner belong together, so separate
// components never share a Marching Cubes cell.
// Errors: CANCELLED; INVALID_ARGUMENT when the label's box exceeds 2^32 voxels.
absl::StatusOr<LabelComponents> find_label_components(const LabelVolume& volume,
                                                      const LabelStatistics& label,
                                                      const ComponentOptions& options,
                                                      const RunContext& context);

}  // namespace labelmesh::volume
