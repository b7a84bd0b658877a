// SPDX-License-Identifier: AGPL-3.0-or-later
// The pipeline options of `labelmesh mesh` and `labelmesh submit`: one set of
// flags, bound to the pipeline's own parameters where they are values, and
// written into the one job-options message both paths run with by the
// pipeline's own writer (make_options).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/job/mesh_params.h"
#include "labelmesh/v1/options.pb.h"

namespace CLI {
class App;
}

namespace labelmesh::client {

struct PipelineFlags {
  // The values the flags set directly, defaults and all.
  MeshParams params;
  // Choices by name, read into `params` by to_mesh_options. An empty
  // surface is the job options' default (net, or poisson under a volume
  // mesh).
  std::string surface;
  std::string normals = "uniform";
  std::string point_reduction = "grid";
  std::string volume = "none";
  std::string coordinates = "lps";
  std::string overlapping = "refuse";
  // Flags that turn a default off.
  bool keep_strands = false;
  bool tet_split_boundary = false;
  bool no_adapt_to_thickness = false;
  bool no_fall_back = false;
  bool file_grid = false;
  // LABEL:EDGE_MM[:DISTANCE_MM], one per label.
  std::vector<std::string> label_sizing;
  // A label table: ITK-SNAP, FreeSurfer or JSON (volume/label_table.h).
  std::string label_names;
  // Passed on as given: the job options' reader sorts them by kind.
  std::vector<std::string> formats{"stl", "vtp"};
};

void add_pipeline_flags(CLI::App& command, PipelineFlags& flags);

// Errors: INVALID_ARGUMENT for a malformed --label-sizing entry or label
// table; NOT_FOUND for a missing label table.
absl::StatusOr<v1::MeshOptions> to_mesh_options(const PipelineFlags& flags);

}  // namespace labelmesh::client
