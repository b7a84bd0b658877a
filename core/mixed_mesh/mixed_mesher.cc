// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/mixed_mesher.h"

#include <chrono>
#include <map>

#include "core/surface/surface_statistics.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::mixed_mesh {
namespace {

// The surface and the core's shell as one boundary: TetGen fills what lies
// between, and carves the shell's inside (the core) out as a cavity.
surface::TriangleMesh layer_boundary(const surface::TriangleMesh& surface, const HexCore& core) {
  surface::TriangleMesh boundary = surface;
  const auto offset = static_cast<uint32_t>(boundary.points.size());
  boundary.points.insert(boundary.points.end(), core.mesh.points.begin(), core.mesh.points.end());
  for (const auto& t : core.shell)
    boundary.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return boundary;
}

// Whether every triangle of `surface` is reachable from the first through
// shared corners.
bool one_piece(const surface::TriangleMesh& surface) {
  std::vector<uint32_t> parent(surface.points.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& t : surface.triangles) {
    parent[root(t[1])] = root(t[0]);
    parent[root(t[2])] = root(t[0]);
  }
  if (surface.triangles.empty()) return true;
  const uint32_t first = root(surface.triangles.front()[0]);
  for (const auto& t : surface.triangles)
    if (root(t[0]) != first) return false;
  return true;
}

// The core without pyramids, trimmed of cubes that stick out on four sides,
// and the hexahedral layer on it. FAILED_PRECONDITION, with the reason, when
// there is no core or the layer misses its floors.
absl::StatusOr<MixedMesh> mesh_with_hex_layer(const SurfaceOracle& oracle,
                                              const surface::TriangleMesh& surface, int32_t label,
                                              const MixedParams& params, const RunContext& context,
                                              MixedFigures& figures) {
  HexCoreParams core_params = params.core;
  core_params.pyramids = false;
  core_params.max_open_faces = 3;
  LABELMESH_ASSIGN_OR_RETURN(auto core,
                             build_hex_core(oracle, surface, label, core_params, context));
  figures.grid_cells += core.grid_cells;
  figures.depth_queries += core.depth_queries;
  figures.core_cells_removed += core.cells_removed;
  if (core.mesh.size() == 0) {
    return absl::FailedPreconditionError(
        cat("too thin for a single ", params.core.cell_mm, " mm cube"));
  }
  MixedMesh cells = std::move(core.mesh);
  if (!params.hexahedra_only) {
    OctreeParams octree = params.octree;
    octree.cell_mm = params.core.cell_mm;
    auto coarse = coarsen_core(cells, octree, figures.octree);
    if (!coarse.ok()) return absl::InternalError(coarse.status().message());
    cells = std::move(*coarse);
  }
  HexLayerParams layer_params = params.layer;
  layer_params.cell_mm = params.core.cell_mm;
  layer_params.split = params.layer.split && !params.hexahedra_only;
  HexLayerFigures layer;
  auto mesh = add_hex_layer(oracle, figures.surface_volume_mm3, std::move(cells), layer_params,
                            context, layer);
  figures.layer = layer;
  return mesh;
}

}  // namespace

absl::StatusOr<MixedMesh> mesh_mixed(const surface::TriangleMesh& surface, int32_t label,
                                     const MixedParams& params, const RunContext& context,
                                     MixedFigures& figures) {
  const auto start = std::chrono::steady_clock::now();
  auto oracle = SurfaceOracle::build(surface);
  if (!oracle.ok()) return absl::FailedPreconditionError(oracle.status().message());
  figures.surface_volume_mm3 = surface::signed_volume(surface);
  if (params.hexahedral_layer || params.hexahedra_only) {
    auto layered = mesh_with_hex_layer(*oracle, surface, label, params, context, figures);
    if (layered.ok() || layered.status().code() != absl::StatusCode::kFailedPrecondition) {
      figures.core_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return layered;
    }
    figures.layer_refused = std::string(layered.status().message());
    // What the refused layer built is not in the mesh.
    figures.octree = {};
    figures.layer = {};
    if (params.hexahedra_only) {
      figures.left_out = true;
      return MixedMesh{};
    }
  }
  auto core = build_hex_core(*oracle, surface, label, params.core, context);
  if (!core.ok()) return core.status();
  figures.grid_cells += core->grid_cells;
  figures.depth_queries += core->depth_queries;
  figures.core_cells_removed += core->cells_removed;
  figures.core_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The core's pieces are known cavities, and TetGen needs no run to find
  // them, unless the surface has cavities of its own (nested shells).
  const bool known = !core->cavity_points.empty() && one_piece(surface);
  LABELMESH_ASSIGN_OR_RETURN(auto tets,
                             volume_mesh::tetrahedralize_around(
                                 layer_boundary(surface, *core), label, params.tetgen,
                                 known ? &core->cavity_points : nullptr, context, figures.tetgen));

  // TetGen keeps input points exactly: the shell's points are found again by
  // their coordinates, so the tetrahedra share the pyramids' nodes.
  MixedMesh mesh = std::move(core->mesh);
  std::map<std::array<double, 3>, uint32_t> shared;
  for (const auto& t : core->shell)
    for (uint32_t v : t) shared.emplace(mesh.points[v], v);
  std::vector<uint32_t> index(tets.points.size());
  size_t matched = 0;
  for (size_t i = 0; i < tets.points.size(); ++i) {
    if (const auto found = shared.find(tets.points[i]); found != shared.end()) {
      index[i] = found->second;
      ++matched;
    } else {
      index[i] = static_cast<uint32_t>(mesh.points.size());
      mesh.points.push_back(tets.points[i]);
    }
  }
  if (matched != shared.size()) {
    return absl::InternalError(
        cat("label ", label, ": ", shared.size() - matched,
            " of the core's boundary points are missing from TetGen's mesh"));
  }
  for (const auto& t : tets.tetrahedra)
    mesh.add(CellType::kTetra, {index[t[0]], index[t[1]], index[t[2]], index[t[3]]}, label);
  return mesh;
}

}  // namespace labelmesh::mixed_mesh
