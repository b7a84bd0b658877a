// SPDX-License-Identifier: AGPL-3.0-or-later
// Coarser hexahedra deep inside a label (paper §2.4.3): the uniform core's
// cubes merge, eight at a time, into octants up to an interior size, while
// the cubes near the core's boundary keep the surface size. Neighbouring
// octants differ by at most one level (2:1 balance, across faces, edges and
// corners). An octant with a finer neighbour has hanging nodes; it becomes
// a transition pattern about a centre node: a pyramid on each plain face,
// four on a face split into quarters, and tetrahedra fanned from the face's
// centre on a face with only edge midpoints. No node hangs in the result.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/mixed_mesh.h"

namespace labelmesh::mixed_mesh {

struct OctreeParams {
  // Edge of the core's cubes (the surface size), mm.
  double cell_mm = 2;
  // Largest octant edge, mm; up to the surface size means no coarsening.
  double interior_mm = 0;
  // Cubes of the surface size kept under the core's boundary before the
  // first coarser octant.
  int surface_layers = 3;
};

struct OctreeFigures {
  // Octants per level, level 0 being the surface size.
  uint64_t octants[8] = {};
  // Octants split to restore the 2:1 balance.
  uint64_t balance_splits = 0;
  // Octants with a finer neighbour, meshed by a transition pattern.
  uint64_t transition_octants = 0;
};

// An octant: its lowest cube on the core's grid, and its level (edge
// 2^level cubes; its anchor a multiple of that).
struct Octant {
  std::array<int64_t, 3> anchor;
  int level = 0;
};

// The cells of `octants` (which tile a region without overlap, their
// neighbours within one level, coordinates below 2^20): a hexahedron each,
// or the transition pattern where a finer neighbour leaves hanging nodes.
// Node (i, j, k) of the grid lies at origin + (i, j, k) × cell_mm.
MixedMesh mesh_octants(const std::vector<Octant>& octants, const std::array<double, 3>& origin,
                       double cell_mm, int32_t label, OctreeFigures& figures);

// The uniform core (hexahedra on one grid of edge cell_mm, as build_hex_core
// emits them, one label) coarsened inside. Its boundary is unchanged: every
// boundary face still belongs to a cube of the surface size. INVALID_ARGUMENT
// when the core holds other cells or cubes off the grid.
absl::StatusOr<MixedMesh> coarsen_core(const MixedMesh& core, const OctreeParams& params,
                                       OctreeFigures& figures);

}  // namespace labelmesh::mixed_mesh
