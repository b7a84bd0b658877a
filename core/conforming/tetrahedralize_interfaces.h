// SPDX-License-Identifier: AGPL-3.0-or-later
// One TetGen mesh of every label at once: the interface surface goes in as a
// piecewise linear complex, so each interface triangle becomes faces shared
// by the tetrahedra on its two sides, and each region TetGen's constrained
// faces close off takes the label the triangles around it face.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/conforming/interface_surface.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/tet_mesh.h"
#include "core/volume_mesh/tetrahedralize.h"

namespace labelmesh::conforming {

// The points of triangles that cross another triangle (TetGen's -d check),
// sorted, without repeats; empty when the surface is free of crossings.
// Errors as for tetrahedralize_interfaces.
absl::StatusOr<std::vector<uint32_t>> crossing_points(const InterfaceSurface& surface);

struct LabelledRegions {
  // Regions (sets of tetrahedra no constrained face separates) found, and
  // those outside every label (cavities the labels enclose), left out.
  size_t regions = 0;
  size_t outside_regions = 0;
  // Constrained faces whose two sides disagree with the interface triangle
  // they lie in; 0 for a faithful mesh.
  size_t mislabelled_faces = 0;
};

// Meshes every label the surface bounds. The surface must not cross itself
// (see crossing_points). Tetrahedra carry their label; outside regions are
// dropped, as are points no tetrahedron uses. Quality switches as in
// volume_mesh::tetrahedralize.
// Errors: INVALID_ARGUMENT for a parameter out of range or a surface too
// small; FAILED_PRECONDITION when TetGen rejects the surface or a region's
// faces disagree on its label; RESOURCE_EXHAUSTED on memory; CANCELLED;
// INTERNAL for TetGen's internal errors or an inverted tetrahedron.
absl::StatusOr<volume_mesh::TetMesh> tetrahedralize_interfaces(
    const InterfaceSurface& surface, const volume_mesh::TetgenParams& params,
    const RunContext& context, volume_mesh::TetgenFigures& figures, LabelledRegions& regions);

}  // namespace labelmesh::conforming
