// SPDX-License-Identifier: AGPL-3.0-or-later
// Writing a run's results: the output surfaces, the volume mesh and the
// report, in one output directory.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/util/run_context.h"

namespace labelmesh {

// Writes surface-label<N>[-<name>].<ext> (output_names.h) per surface and
// format, the scene files (job/scene_format.h), volume.<ext> per volume format,
// then report.json and report.html, in `out_dir` (created if missing), every
// mesh in params.frame. Fills each result's `files` and `scene_files`.
absl::Status write_results(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                           const RunContext& context);

}  // namespace labelmesh
