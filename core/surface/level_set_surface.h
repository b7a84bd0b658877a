// SPDX-License-Identifier: AGPL-3.0-or-later
// A closed surface where a sampled field crosses a level: CGAL's surface
// mesher on the trilinear interpolation of a voxel grid. Run on a label's
// (lightly smoothed) voxel mask just under one half, it gives the Marching Cubes
// surface's shape with the mesher's angle and size guarantees; the fallback
// for labels whose Poisson surface strays from the voxels.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"

namespace labelmesh::surface {

// Samples on a voxel grid placed in patient space.
struct ScalarGrid {
  std::array<int64_t, 3> dims{0, 0, 0};
  // One value per voxel, i fastest.
  std::vector<float> values;
  // LPS mm of grid index (i, j, k): origin + index_to_mm * (i, j, k), the
  // matrix row-major.
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 9> index_to_mm{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

struct LevelSetParams {
  // The surface is where the field crosses this value; above it is inside.
  // Outside the grid the field is taken as below it.
  double level = 0.5;
  // Smallest triangle angle, degrees, in (0, 30].
  double min_angle_deg = 30;
  // Longest triangle edge, mm.
  double max_edge_mm = 0;
  // Largest distance between a triangle's circumcentre and the level set
  // where the triangle's dual Voronoi edge crosses it, mm.
  double max_distance_mm = 0;
};

// The meshed level set: closed, 2-manifold, outward; the same input always
// gives the same mesh. `seeds` (mm) are points on or near the level set, at
// least one on every component of it (a Marching Cubes surface's points do);
// they are moved onto it before meshing. Errors: INVALID_ARGUMENT for bad
// parameters, a grid whose size does not match its values, no seed on the
// level set or nothing above the level; RESOURCE_EXHAUSTED when the mesher
// does not settle within 2,000 field evaluations per seed (and 2,000,000
// more); INTERNAL when the result is not a closed manifold; CANCELLED.
absl::StatusOr<TriangleMesh> mesh_level_set(const ScalarGrid& grid, const LevelSetParams& params,
                                            const std::vector<std::array<double, 3>>& seeds,
                                            const RunContext& context);

}  // namespace labelmesh::surface
