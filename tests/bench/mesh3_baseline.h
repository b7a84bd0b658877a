// SPDX-License-Identifier: AGPL-3.0-or-later
// CGAL Mesh_3 on one label of a volume: the baseline the issue holds our
// Poisson + TetGen + improvement pipeline to. Bench only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

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

struct Mesh3LabelVolume {
  int32_t label = 0;
  double volume_mm3 = 0;
  size_t tetrahedra = 0;
};

struct Mesh3LabelsFigures {
  size_t nodes = 0;
  size_t tetrahedra = 0;
  quality::QualitySummary quality;       // over all cells in the complex
  std::vector<Mesh3LabelVolume> labels;  // one per subdomain (= label value), sorted by label
  double seconds = 0;  // initialisation + refinement, perturb and exude, single-threaded
};

struct Mesh3Sizing {
  double facet_size_mm = 3;
  double facet_distance_mm = 1;
  double cell_size_mm = 3;
};

// Meshes every non-zero label in one Mesh_3 run on the labelled image: one subdomain per label,
// interfaces shared. Every connected component of every label is seeded
// (initialize_triangulation_from_labeled_image), then refined with facet angle 30 degrees,
// radius-edge 3 and `sizing`, then perturbed and exuded. Randomness is seeded fixed so runs
// repeat. Meshed along the image's axes (the direction is ignored: volumes and angles do not
// depend on it). Labels in [0, 65535] only, and no overlapping layers.
absl::StatusOr<Mesh3LabelsFigures> mesh_labels_with_mesh3(const volume::LabelVolume& volume,
                                                          const Mesh3Sizing& sizing);

}  // namespace labelmesh::bench
