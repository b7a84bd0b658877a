// SPDX-License-Identifier: AGPL-3.0-or-later
// What Poisson reconstruction and the surface it starts from are asked
// (smoothing, normals, point thinning), and the bounds that need no CGAL to
// check, so that job options are checked where CGAL is not linked.
#pragma once

#include <cstdint>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh::surface {

// Low-pass smoothing of the staircase surface before its points go to Poisson
// (surface/smooth_surface.h).
struct SmoothingParams {
  // Filter iterations (the degree of the Chebyshev approximation); 0 turns
  // smoothing off. More iterations give a sharper cut-off, not more smoothing.
  int iterations = 20;
  // Pass band in (0, 2): lower removes longer wavelengths. 0.1 flattens the
  // one-voxel staircase and keeps features a few voxels across.
  double pass_band = 0.1;
};

// How vertex normals weigh their triangles (surface/vertex_normals.h).
enum class NormalWeighting {
  // Mean of the unit normals of incident triangles (the paper's choice, and
  // the default): on Marching Cubes surfaces, whose triangles come in a few
  // shapes and sizes, it follows the staircase's overall slope best.
  kUniform,
  // Sum of area-weighted normals: large triangles count more.
  kArea,
};

// How the oriented points are thinned before the solve (the solve's cost grows
// with the point count; Marching Cubes points are far denser than needed).
enum class PointReduction {
  kNone,
  // One input point per cube of side `reduction_cell_mm` (CGAL grid
  // simplification). Kept points lie on the input surface, so the reduction
  // adds no position error; the input surface is within cell * sqrt(3) of
  // some kept point.
  kGrid,
  // CGAL hierarchy simplification: the point set is split in halves across
  // its main axis until each cluster holds at most `cluster_size` points, and
  // each cluster keeps its point nearest the centroid. Kept points lie on the
  // input surface, as with the grid, but the density follows the points
  // rather than a fixed lattice. On the liver, clusters of 3 keep the
  // one-voxel grid's Hausdorff distance with 44 % fewer points, but the
  // sphere's vertices come out rougher (docs/pipeline.md, "Point reduction").
  kHierarchy,
};

// Clusters larger than this thin the points more than any use we measured.
inline constexpr uint32_t kMaxClusterSize = 64;
// A point budget below this thins even a small organ's surface.
inline constexpr uint64_t kMinPointBudget = 1000;

// A point count that 0 turns off (max_points, split_points): otherwise at
// least kMinPointBudget. INVALID_ARGUMENT names `field`.
absl::Status check_point_count(std::string_view field, uint64_t value);

}  // namespace labelmesh::surface
