// SPDX-License-Identifier: AGPL-3.0-or-later
// The conforming volume stage: one tetrahedral mesh of every selected label
// with shared interfaces, and each label's surface taken from it.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// Meshes `labels` of `volume` (conforming/conforming_mesher.h) into
// result.volume, and gives result.surfaces each label's closed surface: its
// interface faces, wound outwards, sharing points with its neighbours'.
// A label without tetrahedra gets a warning. Errors as mesh_conforming's.
absl::Status add_conforming_mesh(const volume::LabelVolume& volume,
                                 const std::vector<int32_t>& labels, const MeshParams& params,
                                 const RunContext& context, MeshResult& result);

}  // namespace labelmesh
