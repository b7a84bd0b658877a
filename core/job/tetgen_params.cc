// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/tetgen_params.h"

#include <cmath>

#include "core/util/text.h"

namespace labelmesh::volume_mesh {

absl::Status check_tetgen_params(const TetgenParams& params) {
  const double ratio = params.radius_edge_ratio;
  if (!std::isfinite(ratio) || ratio < 1.0 || ratio > 100.0) {
    return absl::InvalidArgumentError(
        cat("tet_radius_edge: ", ratio, " is outside [1, 100] (TetGen may not terminate below 1)"));
  }
  const double angle = params.min_dihedral_deg;
  if (!std::isfinite(angle) || angle < 0.0 || angle > 30.0) {
    return absl::InvalidArgumentError(
        cat("tet_min_dihedral_deg: ", angle, " is outside [0, 30] degrees (0: no bound)"));
  }
  const double max_angle = params.max_dihedral_deg;
  if (!std::isfinite(max_angle) || max_angle < 90.0 || max_angle > 179.0) {
    return absl::InvalidArgumentError(
        cat("tet_max_dihedral_deg: ", max_angle, " is outside [90, 179] degrees"));
  }
  const double volume = params.max_volume_mm3;
  if (!std::isfinite(volume) || (volume != 0.0 && (volume < 1e-6 || volume > 1e12))) {
    return absl::InvalidArgumentError(
        cat("tet_max_volume_mm3: ", volume, " is neither 0 (no bound) nor in [1e-6, 1e12] mm^3"));
  }
  return absl::OkStatus();
}

}  // namespace labelmesh::volume_mesh
