// SPDX-License-Identifier: AGPL-3.0-or-later
// Marching Cubes surfaces of labels (paper §2.2), with VTK's discrete flying
// edges: one closed surface per label, in patient (LPS) space, outward.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/volume/label_components.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

class vtkPolyData;

namespace labelmesh::surface {

struct LabelSurface {
  int32_t label = 0;
  TriangleMesh mesh;
};

// Extracts the boundary of each of `labels` (each must be present in
// `statistics`). Each label is cut to its bounding box plus one voxel of
// background, so a label touching the volume's edge still gets a closed
// surface. Vertices sit on voxel faces, halfway between voxel centres.
// Errors: INVALID_ARGUMENT for an absent label, CANCELLED.
absl::StatusOr<std::vector<LabelSurface>> extract_surfaces(
    const volume::LabelVolume& volume, const volume::VolumeStatistics& statistics,
    const std::vector<int32_t>& labels, const RunContext& context);

// Extracts the surface of each component in `ids` (1-based ids into
// `components`), cropped to the component's box: one closed, outward surface
// per component, identical to that component's part of the label's surface.
absl::StatusOr<std::vector<TriangleMesh>> extract_component_surfaces(
    const volume::LabelComponents& components, const std::vector<int32_t>& ids,
    const volume::ImageGeometry& geometry, const RunContext& context);

// The triangles of a contour of a volume's image (whose coordinates are
// voxel indices), with their points in patient (LPS) space.
TriangleMesh to_patient_space(vtkPolyData* contour, const volume::ImageGeometry& geometry);

}  // namespace labelmesh::surface
