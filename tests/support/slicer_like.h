// SPDX-License-Identifier: AGPL-3.0-or-later
// The baseline our smooth surfaces are measured against: the closed-surface
// pipeline 3D Slicer applies to a labelmap segment by default, built from
// the same VTK filters. Per label, discrete flying edges on the label's box,
// then 20 iterations of windowed-sinc smoothing with pass band
// 10^(-4 x 0.5) = 0.01 (Slicer's smoothing factor 0.5), coordinates
// normalised, non-manifold points smoothed, no feature edges kept.
#pragma once

#include <vector>

#include "core/surface/extract_surfaces.h"
#include "core/surface/smooth_surface.h"

namespace labelmesh::testing {

inline surface::SmoothingParams slicer_smoothing() {
  surface::SmoothingParams params;
  params.iterations = 20;
  params.pass_band = 0.01;
  return params;
}

// One smoothed surface per label, in the order of `labels`; empty on error.
inline std::vector<surface::LabelSurface> slicer_like_surfaces(
    const volume::LabelVolume& volume, const volume::VolumeStatistics& statistics,
    const std::vector<int32_t>& labels) {
  auto extracted = surface::extract_surfaces(volume, statistics, labels, RunContext{});
  if (!extracted.ok()) return {};
  for (auto& s : *extracted) {
    auto smooth = surface::smooth_surface(s.mesh, slicer_smoothing(), RunContext{});
    if (!smooth.ok()) return {};
    s.mesh = std::move(*smooth);
  }
  return std::move(*extracted);
}

}  // namespace labelmesh::testing
