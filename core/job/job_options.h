// SPDX-License-Identifier: AGPL-3.0-or-later
// Job options between the proto schema (proto/labelmesh/v1/options.proto) and
// MeshParams: every option's range is checked here and only here.
#pragma once

#include "absl/status/statusor.h"
#include "core/header/image_geometry.h"
#include "core/job/mesh_params.h"
#include "labelmesh/v1/options.pb.h"

namespace labelmesh {

// Errors: INVALID_ARGUMENT naming the option at fault.
absl::StatusOr<MeshParams> params_from_options(const v1::MeshOptions& options);
v1::MeshOptions make_options(const MeshParams& params);

// Sizing in mm against the volume's grid: no edge finer than half a voxel and
// no distance bound finer than a twentieth (the limits the options in voxels
// have). INVALID_ARGUMENT naming the option otherwise.
absl::Status check_sizing_for_grid(const PoissonOptions& poisson,
                                   const volume::ImageGeometry& geometry);

}  // namespace labelmesh
