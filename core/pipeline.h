// The one place that knows the order of the stages: read and check the
// volume, count labels, extract surfaces, measure them, write the results.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/mesh_params.h"
#include "core/run_context.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/triangle_mesh.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

struct StageTiming {
  std::string name;
  double seconds = 0;
};

// The input as read: format, placement and label counts.
struct VolumeSummary {
  volume::ImageFormat format = volume::ImageFormat::kNifti;
  std::string file_voxel_type;
  volume::ImageGeometry geometry;
  volume::VolumeStatistics statistics;
};

struct SurfaceResult {
  int32_t label = 0;
  // Stage that produced the surface: "marching_cubes".
  std::string stage;
  surface::TriangleMesh mesh;
  surface::SurfaceStatistics statistics;
  // Files written for it, relative to the output directory.
  std::vector<std::string> files;
};

struct MeshResult {
  VolumeSummary input;
  std::vector<SurfaceResult> surfaces;
  std::vector<StageTiming> stages;
};

// Reads `path` and counts its labels (what `labelmesh info` shows).
absl::StatusOr<VolumeSummary> summarise_volume(const std::string& path,
                                               const volume::ReadLimits& limits,
                                               const RunContext& context);

// Runs every stage on `path`. Errors: NOT_FOUND / INVALID_ARGUMENT for bad
// input or options (naming the file and field), FAILED_PRECONDITION when the
// volume holds nothing to mesh, CANCELLED, INTERNAL for a failed stage.
absl::StatusOr<MeshResult> run_pipeline(const std::string& path, const MeshParams& params,
                                        const RunContext& context);

// Writes surface-label<N>.<ext> per surface and format, then report.json, in
// `out_dir` (created if missing). Fills each surface's `files`.
absl::Status write_results(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                           const RunContext& context);

}  // namespace labelmesh
