// SPDX-License-Identifier: AGPL-3.0-or-later
// The stages after Marching Cubes for one label (paper §2.2–2.3): split into
// connected components, drop the small ones, repair each, reconstruct each
// with Poisson, then check the result against the Marching Cubes surface.
#pragma once

#include <vector>

#include "absl/status/status.h"
#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/surface/surface_checks.h"
#include "core/util/run_context.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// Voxel size in mm for the options given in voxels: the cube root of the
// voxel volume.
double voxel_size_mm(const volume::ImageGeometry& geometry);

// Appends the "repaired" surface of `label` and, for SurfaceMethod::kPoisson,
// the delivered one; the last appended is marked as the output. The delivery
// guard measures each surface it builds against the label's Marching Cubes
// surface (volume, distances). Poisson comes first on labels at least
// params.poisson.min_thickness_voxels thick (always without fall-back);
// outside `tolerance` the guard tries a finer Poisson surface (only within 1.5
// times the tolerance), then the label's smoothed voxel mask meshed just under
// one half (at the label's sizing, then at half of it), and last, when nothing
// smoother was built, the repaired surface. It delivers the first within the
// tolerance or else the one least outside it; what it tried is in the
// output's `fidelity`. When no attempt could be built, the
// output carries the `error` and no surface. When every component is under
// the size threshold, only a "repaired" entry with the dropped counts (and no
// surface) is appended, unless the label was asked for by name
// (params.labels): then FAILED_PRECONDITION. Adds stage times to `stages`.
// Errors: INVALID_ARGUMENT for bad options, INTERNAL for a failed stage before
// the surfaces, CANCELLED.
absl::Status add_label_surfaces(const volume::LabelVolume& volume,
                                const volume::LabelStatistics& label, const MeshParams& params,
                                const SurfaceTolerance& tolerance, const RunContext& context,
                                std::vector<SurfaceResult>& surfaces,
                                std::vector<StageTiming>& stages);

}  // namespace labelmesh
