// SPDX-License-Identifier: AGPL-3.0-or-later
// A coarser label grid for conforming meshes whose interfaces would be too
// large at the voxels' own resolution: the mesh's size follows the
// interface surface (about two triangles per pair of touching voxels of
// different labels), so a whole-head or whole-body segmentation on a fine
// grid would need several GiB. Blocks of voxels are merged into one voxel
// holding their most common label.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/conforming/interface_budget.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh::conforming {

struct Coarsening {
  // Voxel faces between different labels (unselected ones count as the
  // outside) on the input grid.
  uint64_t interface_faces = 0;
  // Voxels merged along each axis; all 1 when the grid is kept.
  std::array<int, 3> factors{1, 1, 1};
};

// Counts the interface faces of `labels` (every non-zero label when empty)
// and, when they exceed `max_interface_faces` (0: no bound), picks block
// factors that bring them under it: about sqrt(faces / max) times the
// smallest spacing along each axis, as the faces shrink with the square of
// the voxel size.
Coarsening choose_coarsening(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                             uint64_t max_interface_faces);

// `volume` with each block of factors[0] x factors[1] x factors[2] voxels
// (fewer at the far ends) made one voxel holding the block's most common
// selected label or 0 (ties go to a label over 0, then to the smaller
// label): the same directions, the first coarse voxel's centre at the first
// block's centre, int32 voxels.
// Errors: INVALID_ARGUMENT for a factor below 1; RESOURCE_EXHAUSTED when the
// coarse volume cannot be allocated; CANCELLED.
absl::StatusOr<volume::LabelVolume> coarsen_labels(const volume::LabelVolume& volume,
                                                   const std::vector<int32_t>& labels,
                                                   const std::array<int, 3>& factors,
                                                   const RunContext& context);

}  // namespace labelmesh::conforming
