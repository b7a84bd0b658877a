// SPDX-License-Identifier: AGPL-3.0-or-later
// How faithful a label's delivered surface is to its voxels: the figures the
// delivery guard compares with its tolerances, and the attempts it made.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/surface/voxel_fidelity.h"

namespace labelmesh {

// What a surface may differ from its label and still be delivered. Surfaces
// measured against the label's voxels (SurfaceAttempt::voxels) are judged by
// those figures; the others against the label's Marching Cubes surface (of
// the kept components).
struct SurfaceTolerance {
  // |volume change| as a fraction of the voxels' volume (or the Marching
  // Cubes volume).
  double volume_fraction = 0.03;
  // Symmetric Hausdorff distance to the Marching Cubes surface, mm.
  double hausdorff_mm = 0;
  // Voxel centres on the wrong side, as a fraction of the label's boundary
  // voxels, and the farthest any may lie from the surface, voxels.
  double misclassified_fraction = 0.01;
  double misclassified_reach_voxels = 0.5;
  // Hausdorff distance to the voxels' boundary, voxels along each axis.
  double hausdorff_voxels = 1;
};

// The surfaces the delivery guard can build, in the order it tries them.
enum class SurfaceAttemptMethod {
  kNet,             // the labels' shared surface net, smoothed within each voxel
  kNetLighter,      // the same net smoothed half as many rounds (labels alone)
  kPoisson,         // repaired Marching Cubes, CGAL Poisson reconstruction
  kPoissonRefined,  // the same at half the edge and distance bounds
  kMask,            // the smoothed voxel mask meshed by CGAL just under one half
  kMaskRefined,     // the same at half the bounds
  kMaskFinest,      // at a quarter
  kRepaired,        // the repaired Marching Cubes surface itself
};

// The method's name in reports and stages ("net", "poisson_refined", ...).
const char* method_name(SurfaceAttemptMethod method);

// One surface the guard built and measured for a label.
struct SurfaceAttempt {
  SurfaceAttemptMethod method = SurfaceAttemptMethod::kNet;
  // Sizing it was built with, mm (the largest over the label's components).
  double max_edge_mm = 0;
  double max_distance_mm = 0;
  // Empty when it was built; else why it could not be.
  std::string error;
  double volume_change = 0;  // signed fraction of the Marching Cubes volume
  double hausdorff_mm = 0;
  double mean_distance_mm = 0;
  // Where the Hausdorff distance is reached (LPS, mm).
  std::array<double, 3> hausdorff_at{0, 0, 0};
  double min_angle_deg = 0;
  double max_angle_deg = 0;
  // Against the label's voxels; when set, the verdict rests on these.
  std::optional<surface::VoxelFidelity> voxels;
  bool within_tolerance = false;
};

struct SurfaceFidelity {
  SurfaceTolerance tolerance;
  // Enclosed volume of the label's Marching Cubes surface, mm^3.
  double marching_cubes_volume_mm3 = 0;
  // 3 x volume / area of the label's repaired surface, voxels.
  double thickness_voxels = 0;
  // In the order tried; the delivered one is `delivered`.
  std::vector<SurfaceAttempt> attempts;
  size_t delivered = 0;
  bool within_tolerance() const {
    return delivered < attempts.size() && attempts[delivered].within_tolerance;
  }
};

// Labels with fewer voxels than this get the small-label volume tolerance.
inline constexpr uint64_t kSmallLabelVoxels = 1000;

// The tolerance for a label of `voxels` voxels: `volume_percent` (or
// `small_volume_percent` under kSmallLabelVoxels), and `hausdorff_mm`, or when
// that is 0 the largest spacing the segmentation was drawn at.
SurfaceTolerance tolerance_for(uint64_t voxels, const std::array<double, 3>& drawn_spacing,
                               double volume_percent, double small_volume_percent,
                               double hausdorff_mm);

// Whether `attempt`'s figures are within `tolerance` (and it was built): its
// voxel figures when it has them, else those against Marching Cubes.
bool is_within(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance);

// How far outside the tolerance an attempt is: the largest of its figures,
// each over its bound (as is_within chooses them); infinite when it failed. The
// guard delivers the attempt with the least when none is within.
double excess_over(const SurfaceAttempt& attempt, const SurfaceTolerance& tolerance);

}  // namespace labelmesh
