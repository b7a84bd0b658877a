// SPDX-License-Identifier: AGPL-3.0-or-later
// Low-pass smoothing of a staircase surface before Poisson reconstruction:
// VTK's windowed-sinc filter (Taubin, Zhang & Golub, "Optimal surface
// smoothing as filter design", 1996), which removes the voxel-scale ripple
// without the shrinkage of plain Laplacian smoothing.
#pragma once

#include "absl/status/statusor.h"
#include "core/job/poisson_params.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"

namespace labelmesh::surface {

// The same triangles with moved points. Connectivity, orientation and the
// number of points never change. Errors: INVALID_ARGUMENT for bad parameters,
// CANCELLED.
absl::StatusOr<TriangleMesh> smooth_surface(const TriangleMesh& mesh, const SmoothingParams& params,
                                            const RunContext& context);

}  // namespace labelmesh::surface
