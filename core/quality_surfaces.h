// The stages after Marching Cubes for one label (paper §2.2–2.3): split into
// connected components, drop the small ones, repair each, reconstruct each
// with Poisson, then check the result against the Marching Cubes surface.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "core/mesh_params.h"
#include "core/pipeline.h"
#include "core/run_context.h"
#include "core/surface/surface_checks.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// Voxel size in mm for the options given in voxels: the cube root of the
// voxel volume.
double voxel_size_mm(const volume::ImageGeometry& geometry);

// A surface whose distance to Marching Cubes is still to be measured: its
// index in the surfaces vector and the Marching Cubes side of the distance.
struct PendingDistance {
  size_t surface;
  std::unique_ptr<surface::DistanceReference> marching_cubes;
};

// Appends the "repaired" surface of `label` and, for SurfaceMethod::kPoisson,
// the "poisson" one; the last appended is marked as the output, and its
// distance to Marching Cubes is left in `pending` for measure_distances. When
// every component is under the size threshold, only a "repaired" entry with
// the dropped counts (and no surface) is appended, unless the label was asked
// for by name (params.labels): then FAILED_PRECONDITION. Adds stage times to
// `stages`. Errors: INVALID_ARGUMENT for bad options, INTERNAL for a failed
// stage, CANCELLED.
absl::Status add_quality_surfaces(const volume::LabelVolume& volume,
                                  const volume::LabelStatistics& label, const MeshParams& params,
                                  const RunContext& context, std::vector<SurfaceResult>& surfaces,
                                  std::vector<PendingDistance>& pending,
                                  std::vector<StageTiming>& stages);

// Measures each pending surface of `surfaces` against its Marching Cubes
// reference (distance_to_marching_cubes; two threads) and empties `pending`.
// Errors: CANCELLED.
absl::Status measure_distances(std::vector<SurfaceResult>& surfaces,
                               std::vector<PendingDistance>& pending, const RunContext& context);

// measure_distances on a second thread while `other_work` runs on this one,
// which then joins in with what is left of the measuring (TetGen runs on one
// core, so the measuring gets the other, and both at the end). Sets
// `distance_seconds` to the measuring's wall time. Errors: CANCELLED.
absl::Status measure_distances_beside(std::vector<SurfaceResult>& surfaces,
                                      std::vector<PendingDistance>& pending,
                                      const RunContext& context,
                                      const std::function<void()>& other_work,
                                      double& distance_seconds);

}  // namespace labelmesh
