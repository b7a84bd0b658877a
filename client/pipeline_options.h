// SPDX-License-Identifier: AGPL-3.0-or-later
// The pipeline options of `labelmesh mesh` and `labelmesh submit`: one set of
// flags, turned into the one job-options message both paths run with.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/pipeline/mesh_params.h"
#include "labelmesh/v1/options.pb.h"

namespace CLI {
class App;
}

namespace labelmesh::client {

struct PipelineFlags {
  std::vector<int32_t> labels;
  // Empty: the job options' default (net, or poisson under a volume mesh).
  std::string surface;
  PoissonOptions poisson;
  std::string normals = "uniform";
  std::string point_reduction = "grid";
  bool keep_strands = false;
  std::string volume = "none";
  double hex_size_mm = 0;
  double hex_interior_size_mm = 0;
  uint64_t conforming_max_interface_faces = conforming::kDefaultMaxInterfaceFaces;
  volume_mesh::TetgenParams tetgen;
  volume_mesh::ImproveParams improve;
  bool tet_split_boundary = false;
  bool no_adapt_to_thickness = false;
  // LABEL:EDGE_MM[:DISTANCE_MM], one per label.
  std::vector<std::string> label_sizing;
  // A label table: ITK-SNAP, FreeSurfer or JSON (volume/label_table.h).
  std::string label_names;
  GuardOptions guard;
  bool no_fall_back = false;
  std::vector<std::string> formats{"stl", "vtp"};
  std::string coordinates = "lps";
  std::string overlapping = "refuse";
  uint64_t max_voxels = volume::ReadLimits{}.max_voxels;
};

void add_pipeline_flags(CLI::App& command, PipelineFlags& flags);

// Errors: INVALID_ARGUMENT for a malformed --label-sizing entry or label
// table; NOT_FOUND for a missing label table.
absl::StatusOr<v1::MeshOptions> to_mesh_options(const PipelineFlags& flags);

}  // namespace labelmesh::client
