// SPDX-License-Identifier: AGPL-3.0-or-later
// Job options between the proto schema (proto/labelmesh/v1/options.proto) and
// MeshParams: every option's range is checked here and only here.
#pragma once

#include "absl/status/statusor.h"
#include "core/pipeline/mesh_params.h"
#include "labelmesh/v1/options.pb.h"

namespace labelmesh {

// Errors: INVALID_ARGUMENT naming the option at fault.
absl::StatusOr<MeshParams> params_from_options(const v1::MeshOptions& options);
v1::MeshOptions make_options(const MeshParams& params);

}  // namespace labelmesh
