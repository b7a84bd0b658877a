// SPDX-License-Identifier: AGPL-3.0-or-later
// The octree inside a hexahedral core: each transition pattern on its own
// (an octant among random finer neighbours: its pieces valid, their volume
// the octant's, every shared face matched, no hanging node), and whole cores
// coarsened (volume and boundary kept, neighbours within one level).
#include "core/mixed_mesh/octree_core.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/mixed_faces.h"
#include "support/status_matchers.h"

namespace labelmesh::mixed_mesh {
namespace {

using Index = std::array<int64_t, 3>;

// The edge of the octant a cell belongs to: hexahedra their own edge,
// transition pieces twice the largest offset of a corner from their apex
// (the octant's centre, their last node).
double octant_edge(const MixedMesh& mesh, size_t c) {
  const auto& nodes = mesh.cells[c];
  const auto& p = mesh.points;
  if (mesh.types[c] == CellType::kHexahedron) return p[nodes[6]][0] - p[nodes[0]][0];
  const int apex = node_count(mesh.types[c]) - 1;
  double offset = 0;
  for (int k = 0; k < apex; ++k)
    for (int a = 0; a < 3; ++a)
      offset = std::max(offset, std::abs(p[nodes[k]][a] - p[nodes[apex]][a]));
  return 2 * offset;
}

// Neighbours within one level: the octants meeting at any node differ in
// edge by at most a factor of two.
void expect_balanced(const MixedMesh& mesh) {
  std::vector<double> least(mesh.points.size(), 1e300), most(mesh.points.size(), 0);
  for (size_t c = 0; c < mesh.size(); ++c) {
    const double edge = octant_edge(mesh, c);
    for (int k = 0; k < node_count(mesh.types[c]); ++k) {
      least[mesh.cells[c][k]] = std::min(least[mesh.cells[c][k]], edge);
      most[mesh.cells[c][k]] = std::max(most[mesh.cells[c][k]], edge);
    }
  }
  for (size_t v = 0; v < mesh.points.size(); ++v)
    if (most[v] > 0) {
      EXPECT_LE(most[v], 2 * least[v] + 1e-9) << "node " << v;
    }
}

// Nodes in the middle of a cell's edge or of a cell's square face: the
// neighbour there is finer and the cell does not share its nodes.
size_t hanging_nodes(const MixedMesh& mesh) {
  std::map<std::array<double, 3>, int> at;
  for (const auto& p : mesh.points) at[p] = 1;
  auto middle = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::array<double, 3>{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
  };
  size_t hanging = 0;
  for (const CellFace& face : cell_faces(mesh)) {
    for (int k = 0; k < face.size; ++k)
      hanging += at.count(
          middle(mesh.points[face.points[k]], mesh.points[face.points[(k + 1) % face.size]]));
    if (face.size == 4)
      hanging += at.count(middle(mesh.points[face.points[0]], mesh.points[face.points[2]]));
  }
  return hanging;
}

// An octant of edge 2 at (2, 2, 2) and its 26 neighbours of the same size,
// each either whole or split into eight unit cubes at random: every pattern
// the octants can need (a face in quarters, edge midpoints only, corners
// only), many times over.
TEST(OctreeTransitions, EveryPatternIsValidConformingAndFillsItsOctant) {
  std::mt19937 random(2024);
  size_t transitions = 0, pyramids = 0, tetrahedra = 0;
  for (int trial = 0; trial < 600; ++trial) {
    // From one neighbour split to all of them.
    const double share = double(trial % 20 + 1) / 20;
    std::vector<Octant> octants;
    size_t whole = 0;
    for (int64_t z = 0; z <= 4; z += 2)
      for (int64_t y = 0; y <= 4; y += 2)
        for (int64_t x = 0; x <= 4; x += 2) {
          const bool centre = x == 2 && y == 2 && z == 2;
          if (centre || !std::bernoulli_distribution(share)(random)) {
            octants.push_back({{x, y, z}, 1});
            ++whole;
            continue;
          }
          for (int64_t k = 0; k < 8; ++k)
            octants.push_back({{x + (k & 1), y + (k >> 1 & 1), z + (k >> 2 & 1)}, 0});
        }
    OctreeFigures figures;
    const MixedMesh mesh = mesh_octants(octants, {10, -5, 3}, 1.5, 4, figures);
    ASSERT_THAT(check_mixed_mesh(mesh), testing::IsOk());
    const MixedQuality q = measure_mixed_mesh(mesh);
    EXPECT_EQ(q.invalid, 0u) << "trial " << trial;
    const double cube = 1.5 * 1.5 * 1.5;
    EXPECT_NEAR(q.volume_mm3, cube * 216, 1e-9) << "trial " << trial;
    // The pieces of the octants of edge 2 (3 mm) fill them exactly.
    double octant_volume = 0;
    for (size_t c = 0; c < mesh.size(); ++c)
      if (octant_edge(mesh, c) > 2) octant_volume += cell_signed_volume(mesh, c);
    EXPECT_NEAR(octant_volume, 8 * cube * double(whole), 1e-9) << "trial " << trial;
    EXPECT_THAT(check_conformity(mesh), testing::IsOk()) << "trial " << trial;
    EXPECT_EQ(hanging_nodes(mesh), 0u) << "trial " << trial;
    expect_balanced(mesh);
    if (q.pyramid_aspect_ratio_min) {
      EXPECT_GE(*q.pyramid_aspect_ratio_min, 0.45);
    }
    if (q.tetrahedra > 0) {
      EXPECT_GE(q.tetra_summary.min, 0.5);
    }
    EXPECT_EQ(q.cell_summary.good, int64_t(mesh.size()));
    transitions += figures.transition_octants;
    pyramids += q.pyramids;
    tetrahedra += q.tetrahedra;
  }
  std::printf("600 neighbourhoods: %zu transitions, %zu pyramids, %zu tetrahedra\n", transitions,
              pyramids, tetrahedra);
  EXPECT_GT(transitions, 500u);
  EXPECT_GT(pyramids, 0u);
  EXPECT_GT(tetrahedra, 0u);
}

// A 20-cube block, as build_hex_core emits it, coarsened up to octants of 8
// cubes: the same volume and outer squares, fewer nodes, neighbours within a
// level, and every face matched.
TEST(OctreeCore, ABlockCoarsensInsideAndKeepsItsBoundary) {
  constexpr int64_t n = 20;
  constexpr double h = 2;
  MixedMesh core;
  std::map<Index, uint32_t> nodes;
  auto node = [&](const Index& v) {
    auto [found, added] = nodes.emplace(v, uint32_t(core.points.size()));
    if (added)
      core.points.push_back({-7 + double(v[0]) * h, 3 + double(v[1]) * h, double(v[2]) * h});
    return found->second;
  };
  const Index corners[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int64_t z = 0; z < n; ++z)
    for (int64_t y = 0; y < n; ++y)
      for (int64_t x = 0; x < n; ++x) {
        std::array<uint32_t, 8> hex{};
        for (int k = 0; k < 8; ++k)
          hex[k] = node({x + corners[k][0], y + corners[k][1], z + corners[k][2]});
        core.add(CellType::kHexahedron, hex, 9);
      }
  OctreeParams params;
  params.cell_mm = h;
  params.interior_mm = 8 * h;
  OctreeFigures figures;
  auto coarse = coarsen_core(core, params, figures);
  ASSERT_THAT(coarse, testing::IsOk());
  ASSERT_THAT(check_mixed_mesh(*coarse), testing::IsOk());
  const MixedQuality q = measure_mixed_mesh(*coarse);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_NEAR(q.volume_mm3, double(n * n * n) * h * h * h, 1e-6);
  const Conformity c = check_conformity(*coarse);
  EXPECT_THAT(c, testing::IsOk());
  EXPECT_EQ(hanging_nodes(*coarse), 0u);
  EXPECT_EQ(c.boundary_faces, size_t(6 * n * n));
  for (const CellFace& face : label_boundary_faces(*coarse)) {
    EXPECT_EQ(coarse->types[face.cell], CellType::kHexahedron);
    EXPECT_NEAR(octant_edge(*coarse, face.cell), h, 1e-12);
  }
  EXPECT_GT(figures.octants[1], 0u);
  EXPECT_GT(figures.octants[2], 0u);
  EXPECT_GT(figures.transition_octants, 0u);
  EXPECT_LT(coarse->points.size(), core.points.size());
  expect_balanced(*coarse);
  std::printf("octants per level %llu %llu %llu %llu, %llu transitions; %zu nodes (uniform %zu)\n",
              (unsigned long long)figures.octants[0], (unsigned long long)figures.octants[1],
              (unsigned long long)figures.octants[2], (unsigned long long)figures.octants[3],
              (unsigned long long)figures.transition_octants, coarse->points.size(),
              core.points.size());

  // A cube off the grid is refused; no interior size leaves the core as it is.
  MixedMesh shifted = core;
  for (int k = 0; k < 8; ++k) shifted.points[shifted.cells[0][k]][0] += 0.3;
  EXPECT_EQ(coarsen_core(shifted, params, figures).status().code(),
            absl::StatusCode::kInvalidArgument);
  params.interior_mm = 0;
  auto same = coarsen_core(core, params, figures);
  ASSERT_THAT(same, testing::IsOk());
  EXPECT_EQ(same->size(), core.size());
}

}  // namespace
}  // namespace labelmesh::mixed_mesh
