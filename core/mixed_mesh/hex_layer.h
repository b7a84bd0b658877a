// SPDX-License-Identifier: AGPL-3.0-or-later
// A layer of hexahedra from a hexahedral core out to the label's surface:
// each boundary square of the core is extruded along smoothed node normals
// until its corners meet the surface (the paper's projection, §2.4.4 option
// 2), the core's boundary nodes settle at a common depth below the surface,
// and a pattern search moves nodes without ever worsening the worst cell
// around them. A hexahedron still below the Jacobian floor is split into six
// pyramids about an inner point when all six clear the floors. The layer is
// delivered only when every cell clears them and the volume matches the
// surface's; otherwise the caller falls back to another layer.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/mixed_mesh/surface_oracle.h"
#include "core/util/run_context.h"

namespace labelmesh::mixed_mesh {

struct HexLayerParams {
  // Edge of the core's cubes, mm: sets the search's steps.
  double cell_mm = 2;
  // Least Jacobian ratio of any hexahedron or pyramid (paper §2.4.1).
  double jacobian_floor = 0.3;
  // Least signed aspect ratio of a pyramid. Tetrahedra (of an octree's
  // transitions) must be Table 1 "good": Q above 0.2.
  double aspect_floor = 0.2;
  // Largest |volume / surface volume - 1|.
  double volume_tolerance = 0.01;
  // Rounds of averaging the node normals over neighbouring squares.
  int normal_smoothing = 3;
  // Whether a poor hexahedron may become six pyramids; off for hexahedra only.
  bool split = true;
};

struct HexLayerFigures {
  uint64_t layer_hexahedra = 0;
  uint64_t split_hexahedra = 0;
  // Largest distance of an outer node to the surface, mm.
  double boundary_distance_max_mm = 0;
  // The layered mesh's volume against the surface's (volume / surface - 1).
  double volume_change = 0;
};

// The core (cells of one label whose boundary faces are the squares of
// build_hex_core's cubes, a manifold; octree_core.h may have coarsened its
// inside) with the layer added, or
// FAILED_PRECONDITION saying which floor the layer misses; CANCELLED when a
// stop was requested. `surface_volume_mm3` is the volume the surface encloses.
absl::StatusOr<MixedMesh> add_hex_layer(const SurfaceOracle& oracle, double surface_volume_mm3,
                                        MixedMesh core, const HexLayerParams& params,
                                        const RunContext& context, HexLayerFigures& figures);

// The six pyramids of a hexahedron (VTK order) about an inner apex, one on
// each face wound towards the apex: the apex a pattern search finds, from the
// centroid, where every pyramid's Jacobian ratio and signed aspect ratio
// clear the floors; none when no such apex was found.
std::optional<std::array<double, 3>> split_apex(const std::array<std::array<double, 3>, 8>& hex,
                                                const HexLayerParams& params);
// The six pyramids, as node indices, of the hexahedron `hex` about `apex`.
std::array<std::array<uint32_t, 8>, 6> pyramids_of(const std::array<uint32_t, 8>& hex,
                                                   uint32_t apex);

// The rank the layer's search improves: for a hexahedron the smaller of its
// Jacobian ratio and twice its scaled Jacobian (the ratio alone misses
// shear); for a pyramid the smaller of its Jacobian ratio and signed aspect
// ratio; for a wedge its Jacobian ratio; for a tetrahedron Q. Negative for an
// inverted cell. Precondition: check_mixed_mesh(mesh) is OK.
double layer_cell_rank(const MixedMesh& mesh, size_t cell);

}  // namespace labelmesh::mixed_mesh
