// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed-element volume meshes of a label (paper §2.4.3-2.4.4, built our
// way): hexahedra of a grid fill the inside (hex_core.h), a pyramid on each
// of the core's boundary squares turns it into triangles, and TetGen fills
// the layer between those triangles and the label's surface with
// tetrahedra, keeping both boundaries as given. Every element meets its
// neighbours face to face, the outer boundary is the surface itself, and
// no element is inverted.
#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/hex_core.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/tetrahedralize.h"

namespace labelmesh::mixed_mesh {

struct MixedParams {
  HexCoreParams core;
  // For the tetrahedra of the layer. The improvement pass does not run: with
  // both of the layer's boundaries fixed it lifted none of the liver's worst
  // tetrahedra, which sit where two pyramids meet at a concave edge.
  volume_mesh::TetgenParams tetgen;
};

struct MixedFigures {
  uint64_t grid_cells = 0;
  uint64_t depth_queries = 0;
  uint64_t core_cells_removed = 0;
  volume_mesh::TetgenFigures tetgen;
  double core_seconds = 0;
};

// The mixed mesh of the region inside `surface` (closed, oriented outwards),
// every element labelled `label`. A label too thin for a single cube is all
// tetrahedra. Errors: those of SurfaceOracle::build and tetrahedralize
// (FAILED_PRECONDITION for a self-intersecting surface), CANCELLED, and
// INTERNAL when TetGen's points cannot be matched to the core's.
absl::StatusOr<MixedMesh> mesh_mixed(const surface::TriangleMesh& surface, int32_t label,
                                     const MixedParams& params, const RunContext& context,
                                     MixedFigures& figures);

}  // namespace labelmesh::mixed_mesh
