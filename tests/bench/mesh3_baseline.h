// SPDX-License-Identifier: AGPL-3.0-or-later
// CGAL Mesh_3 on one label of a volume: the baseline the issue holds our
// Poisson + TetGen + improvement pipeline to. Bench only.
#pragma once

#include <cstddef>
#include <cstdint>

#include "absl/status/statusor.h"
#include "core/quality/element_quality.h"
#include "core/volume/label_volume.h"

namespace labelmesh::bench {

struct Mesh3Figures {
  size_t nodes = 0;
  size_t tetrahedra = 0;
  quality::QualitySummary quality;
  double seconds = 0;  // make_mesh_3 alone, single-threaded
};

// Meshes the voxels equal to `label` (a binary image) with Mesh_3's labelled
// image domain: facet angle 30 degrees, facet size 2 mm, facet distance
// 0.5 mm, cell size 3 mm, radius-edge 3. Axis-aligned volumes only.
absl::StatusOr<Mesh3Figures> mesh_label_with_mesh3(const volume::LabelVolume& volume,
                                                   int32_t label);

}  // namespace labelmesh::bench
