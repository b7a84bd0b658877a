// SPDX-License-Identifier: AGPL-3.0-or-later
// The mixed-element volume stage: a mesh of hexahedra, pyramids and
// tetrahedra for every label's output surface (mixed_mesh/mixed_mesher.h),
// measured (§2.4.1) and checked for conformity.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/mixed_mesher.h"
#include "core/pipeline/label_tet_meshes.h"
#include "core/util/run_context.h"

namespace labelmesh {

struct MixedVolumeResult {
  mixed_mesh::MixedMesh mesh;
  mixed_mesh::MixedQuality quality;
  mixed_mesh::Conformity conformity;
  // The cube edge used, mm.
  double cell_mm = 0;
  // The largest octant's edge asked for, mm; 0 for one size.
  double interior_mm = 0;
  // Hexahedra only (VolumeMethod::kHex).
  bool hexahedra_only = false;
  // Summed over the labels (the layer's boundary distance: the largest).
  mixed_mesh::MixedFigures figures;
  // A label and why its hexahedral layer was refused.
  struct Refusal {
    int32_t label = 0;
    std::string reason;
  };
  // Labels that got the tetrahedral layer instead.
  std::vector<Refusal> tetrahedral_layer_labels;
  // Labels with no volume mesh (hexahedra only).
  std::vector<Refusal> labels_left_out;
  // Volume the labels' surfaces enclose, mm³.
  double surface_volume_mm3 = 0;
  double seconds = 0;
  // Files written for it, relative to the output directory.
  std::vector<std::string> files;
};

// Meshes each boundary on its own (labels do not share nodes), checks each
// label's conformity (summed in `conformity`), then measures the whole. A
// label left out (hexahedra only) is listed, not an error.
// Errors: those of mixed_mesh::mesh_mixed, naming the label; INTERNAL when
// a label's mesh fails check_mixed_mesh.
absl::StatusOr<MixedVolumeResult> mesh_labels_mixed(const std::vector<LabelBoundary>& boundaries,
                                                    const mixed_mesh::MixedParams& params,
                                                    const RunContext& context);

}  // namespace labelmesh
