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

const char* method_name(SurfaceAttemptMethod method) {
  switch (method) {
    case SurfaceAttemptMethod::kNet:
      return "net";
    case SurfaceAttemptMethod::kNetLighter:
      return "net_lighter";
    case SurfaceAttemptMethod::kPoisson:
      return "poisson";
    case SurfaceAttemptMethod::kPoissonRefined:
      return "poisson_refined";
    case SurfaceAttemptMethod::kMask:
      return "mask";
    case SurfaceAttemptMethod::kMaskRefined:
      return "mask_refined";
    case SurfaceAttemptMethod::kMaskFinest:
      return "mask_finest";
    case SurfaceAttemptMethod::kRepaired:
      return "repaired";
  }
  return "unknown";
}

bool is_within(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance) {
  return attempt.error.empty() && excess_over(attempt, tolerance) <= 1;
}

double excess_over(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance) {
  if (!attempt.error.empty()) return std::numeric_limits<double>::infinity();
  if (attempt.voxels) {
    const auto& v = *attempt.voxels;
    return std::max({std::abs(v.volume_change) / tolerance.volume_fraction,
                     v.misclassified_fraction() / tolerance.misclassified_fraction,
                     v.farthest_misclassified_voxels / tolerance.misclassified_reach_voxels,
                     v.hausdorff_voxels / tolerance.hausdorff_voxels});
  }
  return std::max(std::abs(attempt.volume_change) / tolerance.volume_fraction,
                  attempt.hausdorff_mm / tolerance.hausdorff_mm);
}

}  // namespace labelmesh
