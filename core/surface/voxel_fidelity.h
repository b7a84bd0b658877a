// SPDX-License-Identifier: AGPL-3.0-or-later
// How faithful a closed surface is to the voxels of its label, not to their
// Marching Cubes staircase: the enclosed volume against the voxels', the
// voxel centres the surface puts on the wrong side, the distance to the
// voxels' boundary in voxels along each axis, and how much of the surface
// still faces along a voxel axis (the terraces a staircase leaves).
#pragma once

#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh::surface {

struct VoxelFidelity {
  // The label's voxels times the voxel volume, mm^3.
  double voxel_volume_mm3 = 0;
  // Enclosed volume over the voxels' volume, minus one.
  double volume_change = 0;
  // Voxels of the label with a face neighbour of another label (or outside
  // the volume).
  uint64_t boundary_voxels = 0;
  // Voxel centres on the wrong side of the surface, among the label's
  // boundary voxels and their face neighbours outside the label.
  uint64_t misclassified = 0;
  // The farthest of those from the surface, in voxels along each axis.
  double farthest_misclassified_voxels = 0;
  // Symmetric Hausdorff distance to the voxels' boundary, each axis measured
  // in its own voxel spacing.
  double hausdorff_voxels = 0;
  // Share of the area (outside the caps where the label is cut by the
  // volume's edge) whose normal lies within 10 degrees of a voxel axis.
  double axis_aligned_share = 0;

  double misclassified_fraction() const {
    return boundary_voxels > 0 ? double(misclassified) / double(boundary_voxels) : 0;
  }
};

// Normals within this angle of a voxel axis count as axis-aligned.
inline constexpr double kAxisAlignedDeg = 10;

// Every figure but hausdorff_voxels, for `mesh` (closed, outward, LPS) against
// the voxels of `label` in `volume`. Errors: INVALID_ARGUMENT for a voxel
// type labelmesh does not hold; CANCELLED.
absl::StatusOr<VoxelFidelity> measure_voxel_fidelity(const TriangleMesh& mesh,
                                                     const volume::LabelVolume& volume,
                                                     const volume::LabelStatistics& label,
                                                     const RunContext& context);

// The share of `mesh`'s area facing along a voxel axis of `geometry`
// (kAxisAlignedDeg), leaving out triangles outside the voxel centres' box.
double axis_aligned_share(const TriangleMesh& mesh, const volume::ImageGeometry& geometry);

// The same share with each triangle facing along `normal_at` its centroid
// (LPS) instead of its own normal: a true shape's share, sampled on `mesh`.
double axis_aligned_share(const TriangleMesh& mesh, const volume::ImageGeometry& geometry,
                          const std::function<geometry::Vec3(const geometry::Vec3&)>& normal_at);

// The Hausdorff distance, in voxels along each axis, between `mesh` and
// `staircase` when both have the same triangles (a point moved from its
// staircase position): the largest move bounds it, as each triangle maps
// affinely onto its staircase triangle.
double corresponding_hausdorff_voxels(const TriangleMesh& mesh, const TriangleMesh& staircase,
                                      const volume::ImageGeometry& geometry);

// The same for any two surfaces, sampled at their points and triangle
// centroids; distances beyond 2 voxels count as 2.
double sampled_hausdorff_voxels(const TriangleMesh& mesh, const TriangleMesh& staircase,
                                const volume::ImageGeometry& geometry, const RunContext& context);

}  // namespace labelmesh::surface
