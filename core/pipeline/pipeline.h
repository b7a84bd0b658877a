// SPDX-License-Identifier: AGPL-3.0-or-later
// The one place that knows the order of the stages: read and check the
// volume, count labels, extract surfaces, measure them, mesh the volume.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"
#include "core/volume_mesh/improve_tet_mesh.h"

namespace labelmesh {

// Reads `path` and counts its labels (what `labelmesh info` shows).
absl::StatusOr<VolumeSummary> summarise_volume(const std::string& path,
                                               const volume::ReadLimits& limits,
                                               const RunContext& context);

// The improvement pass's settings for a run on a volume with `geometry`: the
// options' target quality, TetGen's volume bound and, for Poisson surfaces,
// the peel depth (the Poisson distance bound in mm).
volume_mesh::ImproveParams improve_params_for(const MeshParams& params,
                                              const volume::ImageGeometry& geometry);

// Runs every stage on `path`. Errors: NOT_FOUND / INVALID_ARGUMENT for bad
// input or options (naming the file and field), FAILED_PRECONDITION when the
// volume holds nothing to mesh, CANCELLED, INTERNAL for a failed stage.
absl::StatusOr<MeshResult> run_pipeline(const std::string& path, const MeshParams& params,
                                        const RunContext& context);

// The same on a volume already in memory (phantoms, tests).
absl::StatusOr<MeshResult> run_pipeline_on_volume(volume::LabelVolume volume,
                                                  const MeshParams& params,
                                                  const RunContext& context);

}  // namespace labelmesh
