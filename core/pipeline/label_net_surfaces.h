// SPDX-License-Identifier: AGPL-3.0-or-later
// The default surfaces: every label cut from one multi-label surface net
// (conforming/label_interfaces.h), so touching labels share their
// triangles, each judged by the delivery guard against its own voxels.
#pragma once

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "core/pipeline/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// Appends each label's output surface. The guard's ladder, in order:
//   1. poisson: only for a label that touches no other selected label, is at
//      least params.poisson.min_thickness_voxels thick and lies on a grid no
//      more anisotropic than params.net.poisson_max_anisotropy (the Poisson
//      path with its own guard, label_surfaces.h);
//   2. net: the label's part of the shared net;
//   3. the Poisson path with its mask fallbacks, when neither is within the
//      tolerance.
// Every attempt is measured against the label's voxels (volume,
// misclassified voxel centres, Hausdorff distance to the voxels' boundary);
// the first within the tolerance is delivered, else the one least outside
// it. `layer_of[i]` is the layer of `labels[i]`; `tolerance_of[i]` its
// tolerance. Errors: CANCELLED; INVALID_ARGUMENT for bad options.
absl::Status add_net_surfaces(const std::vector<volume::LabelVolume>& layers,
                              const std::vector<size_t>& layer_of,
                              const volume::VolumeStatistics& statistics,
                              const std::vector<int32_t>& labels,
                              const std::vector<SurfaceTolerance>& tolerance_of,
                              const MeshParams& params, const RunContext& context,
                              std::vector<SurfaceResult>& surfaces,
                              std::vector<StageTiming>& stages);

}  // namespace labelmesh
