// The stages after Marching Cubes for one label (paper §2.2–2.3): split into
// connected components, drop the small ones, repair each, reconstruct each
// with Poisson, then check the result against the Marching Cubes surface.
#pragma once

#include <vector>

#include "absl/status/status.h"
#include "core/mesh_params.h"
#include "core/pipeline.h"
#include "core/run_context.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// Voxel size in mm for the options given in voxels: the cube root of the
// voxel volume.
double voxel_size_mm(const volume::ImageGeometry& geometry);

// Appends the "repaired" surface of `label` and, for SurfaceMethod::kPoisson,
// the "poisson" one; the last appended is marked as the output and carries
// the Marching Cubes reference for measure_distances. Adds stage times to
// `stages`. Errors: INVALID_ARGUMENT for bad options,
// FAILED_PRECONDITION when every component is under the size threshold,
// INTERNAL for a failed stage, CANCELLED.
absl::Status add_quality_surfaces(const volume::LabelVolume& volume,
                                  const volume::LabelStatistics& label, const MeshParams& params,
                                  const RunContext& context, std::vector<SurfaceResult>& surfaces,
                                  std::vector<StageTiming>& stages);

// Measures each surface that carries a Marching Cubes reference against it
// (distance_to_marching_cubes), then drops the reference. Uses two threads.
// Errors: CANCELLED.
absl::Status measure_distances(std::vector<SurfaceResult>& surfaces, const RunContext& context);

}  // namespace labelmesh
