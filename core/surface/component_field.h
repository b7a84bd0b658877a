// SPDX-License-Identifier: AGPL-3.0-or-later
// One label component's voxel mask as a field for the level-set mesher: 1 in
// the component, 0 elsewhere, optionally smoothed with a Gaussian so the
// level set at one half loses the voxels' staircase.
#pragma once

#include "absl/status/statusor.h"
#include "core/surface/level_set_surface.h"
#include "core/volume/label_components.h"
#include "core/volume/label_volume.h"

namespace labelmesh::surface {

// The mask of component `id` (1-based, into `components`) on its bounding
// box, padded with background by enough voxels for the smoothing, placed in
// patient space by `geometry`. `sigma_voxels` is the Gaussian's standard
// deviation along each voxel axis, in that axis's voxels; 0 leaves the mask
// as it is. Errors: INVALID_ARGUMENT for an unknown id or a negative sigma.
absl::StatusOr<ScalarGrid> component_field(const volume::LabelComponents& components, int32_t id,
                                           const volume::ImageGeometry& geometry,
                                           double sigma_voxels);

}  // namespace labelmesh::surface
