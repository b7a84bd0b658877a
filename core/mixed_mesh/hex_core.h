// SPDX-License-Identifier: AGPL-3.0-or-later
// The hexahedral core of a label: the cubes of a grid in patient space that
// lie inside the surface with room to spare, each boundary face of the core
// capped by a pyramid that turns its square into four triangles. What is
// left between those triangles and the surface is filled with tetrahedra
// (mixed_mesher.h), so every element meets its neighbours face to face.
#pragma once

#include <array>
#include <cstdint>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/mixed_mesh/surface_oracle.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"

namespace labelmesh::mixed_mesh {

struct HexCoreParams {
  // Edge of the cubes, mm.
  double cell_mm = 2;
  // Pyramid apex height over its base, as a fraction of the edge, at most
  // 0.45 (at 0.5 two pyramids at a concave edge share their apex). Lower
  // opens the gap where two pyramids meet at a concave edge of the core
  // (their triangles there lie atan(2a) and 90° - atan(2a) off one face).
  double apex_height = 0.3;
  // Room left between the core and its pyramids and the surface, as a
  // fraction of the edge, for the tetrahedra to fill.
  double margin = 0.1;
  // Whether each boundary square gets its pyramid and shell triangles; off
  // when a layer of hexahedra (hex_layer.h) covers the core instead.
  bool pyramids = true;
  // Cubes with more boundary faces than this are trimmed too: a cube
  // sticking out on four sides makes poor layer cells around it.
  int max_open_faces = 6;
  unsigned threads = 1;
};

struct HexCore {
  // Hexahedra and pyramids, labelled; points are grid nodes and apexes.
  MixedMesh mesh;
  // The pyramids' side triangles, on mesh.points' indices, wound towards the
  // core: the inner boundary of the region the tetrahedra fill.
  std::vector<std::array<uint32_t, 3>> shell;
  // A point inside each face-connected piece of the core: the cavities the
  // tetrahedra leave.
  std::vector<std::array<double, 3>> cavity_points;
  // Grid cells examined, and those that needed an exact depth.
  uint64_t grid_cells = 0;
  uint64_t depth_queries = 0;
  // Cells taken out of the core to keep its boundary a manifold whose
  // pyramids stay inside the surface.
  uint64_t cells_removed = 0;
};

// The core of the region inside `surface` (closed, oriented outwards; its
// bounding box sizes the grid). A cube belongs to it when its centre is at
// least (√3/2 + margin) × edge deep, so the whole cube is inside; the core is
// then trimmed until its boundary is a manifold (no two cubes meeting at an
// edge or a corner only) and every boundary face's pyramid lies at least
// margin × edge inside. The grid is aligned with the LPS axes. May be empty.
// CANCELLED when a stop was requested.
absl::StatusOr<HexCore> build_hex_core(const SurfaceOracle& oracle,
                                       const surface::TriangleMesh& surface, int32_t label,
                                       const HexCoreParams& params, const RunContext& context);

}  // namespace labelmesh::mixed_mesh
