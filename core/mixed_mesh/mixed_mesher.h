// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed-element volume meshes of a label (paper §2.4.3-2.4.4, built our
// way): hexahedra of a grid fill the inside (hex_core.h) and a layer of
// hexahedra, with a few split into pyramids, reaches out to the surface
// (hex_layer.h). Where that layer misses its floors the label gets the
// tetrahedral layer instead: a pyramid on each of the core's boundary
// squares turns it into triangles, and TetGen fills the layer between those
// triangles and the surface, keeping both boundaries as given. Either way
// every element meets its neighbours face to face and none is inverted.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/hex_core.h"
#include "core/mixed_mesh/hex_layer.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/mixed_mesh/octree_core.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"
#include "core/volume_mesh/tetrahedralize.h"

namespace labelmesh::mixed_mesh {

struct MixedParams {
  HexCoreParams core;
  // The hexahedral layer; its cell_mm is the core's.
  HexLayerParams layer;
  // Coarser octants inside the hexahedral layer's core (its cell_mm is the
  // core's); not with hexahedra_only, nor with the tetrahedral layer.
  OctreeParams octree;
  // Hexahedra only: no split into pyramids, and no tetrahedral layer to fall
  // back to. A label whose layer misses the floors is left out.
  bool hexahedra_only = false;
  // Off: the tetrahedral layer without trying the hexahedral one.
  bool hexahedral_layer = true;
  // For the tetrahedra of the layer. The improvement pass does not run: with
  // both of the layer's boundaries fixed it lifted none of the liver's worst
  // tetrahedra, which sit where two pyramids meet at a concave edge.
  volume_mesh::TetgenParams tetgen;
};

struct MixedFigures {
  uint64_t grid_cells = 0;
  uint64_t depth_queries = 0;
  uint64_t core_cells_removed = 0;
  // Volume the surface encloses, mm³.
  double surface_volume_mm3 = 0;
  OctreeFigures octree;
  HexLayerFigures layer;
  // Why the hexahedral layer was refused; empty when it was delivered.
  std::string layer_refused;
  // Set when the label was left out (hexahedra only): an empty mesh.
  bool left_out = false;
  volume_mesh::TetgenFigures tetgen;
  double core_seconds = 0;
};

// The mixed mesh of the region inside `surface` (closed, oriented outwards),
// every element labelled `label`. A label too thin for a single cube is all
// tetrahedra; with hexahedra_only it is left out (an empty mesh, and
// figures.left_out and layer_refused say so). Errors: those of SurfaceOracle::build and
// tetrahedralize (FAILED_PRECONDITION for a self-intersecting surface), CANCELLED, and INTERNAL
// when TetGen's points cannot be matched to the core's.
absl::StatusOr<MixedMesh> mesh_mixed(const surface::TriangleMesh& surface, int32_t label,
                                     const MixedParams& params, const RunContext& context,
                                     MixedFigures& figures);

}  // namespace labelmesh::mixed_mesh
