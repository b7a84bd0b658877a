// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/surface_fidelity.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace labelmesh {

SurfaceTolerance tolerance_for(uint64_t voxels, const std::array<double, 3>& drawn_spacing,
                               double volume_percent, double small_volume_percent,
                               double hausdorff_mm) {
  SurfaceTolerance tolerance;
  tolerance.volume_fraction =
      (voxels < kSmallLabelVoxels ? small_volume_percent : volume_percent) / 100;
  tolerance.hausdorff_mm = hausdorff_mm > 0
                               ? hausdorff_mm
                               : *std::max_element(drawn_spacing.begin(), drawn_spacing.end());
  return tolerance;
}

bool is_within(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance) {
  return attempt.error.empty() && std::abs(attempt.volume_change) <= tolerance.volume_fraction &&
         attempt.hausdorff_mm <= tolerance.hausdorff_mm;
}

double excess_over(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance) {
  if (!attempt.error.empty()) return std::numeric_limits<double>::infinity();
  return std::max(std::abs(attempt.volume_change) / tolerance.volume_fraction,
                  attempt.hausdorff_mm / tolerance.hausdorff_mm);
}

}  // namespace labelmesh
