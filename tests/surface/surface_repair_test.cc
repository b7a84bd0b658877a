// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/surface_repair.h"

#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/shape_predicates.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/label_statistics.h"
#include "support/label_grid.h"
#include "support/status_matchers.h"

namespace labelmesh::surface {
namespace {

using Point = std::array<double, 3>;

// The Marching Cubes surface of a 4x4x4 block: closed, manifold, clean.
TriangleMesh block_surface() {
  const auto v = testing::label_grid({8, 8, 8}, [](int i, int j, int k) -> uint8_t {
    return (i >= 2 && i <= 5 && j >= 2 && j <= 5 && k >= 2 && k <= 5) ? 1 : 0;
  });
  const auto stats = volume::compute_label_statistics(v);
  auto surfaces = extract_surfaces(v, stats, {1}, RunContext{});
  EXPECT_THAT(surfaces, testing::IsOk());
  return surfaces.ok() ? (*surfaces)[0].mesh : TriangleMesh{};
}

TriangleMesh repair(const TriangleMesh& mesh, RepairCounts& counts) {
  auto repaired = repair_surface(mesh, RepairParams{}, RunContext{}, counts);
  EXPECT_THAT(repaired, testing::IsOk());
  return repaired.ok() ? std::move(*repaired) : TriangleMesh{};
}

void expect_clean(const TriangleMesh& mesh) {
  const auto s = compute_surface_statistics(mesh);
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_GT(s.volume_mm3, 0) << "must face outwards";
}

std::set<Point> point_set(const TriangleMesh& mesh) {
  return {mesh.points.begin(), mesh.points.end()};
}

// The two triangles on either side of the edge (a, b) of triangle `t`.
std::pair<size_t, size_t> triangles_on_edge(const TriangleMesh& mesh, size_t t) {
  const uint32_t a = mesh.triangles[t][0], b = mesh.triangles[t][1];
  for (size_t u = 0; u < mesh.triangles.size(); ++u) {
    const auto& o = mesh.triangles[u];
    for (int c = 0; c < 3; ++c) {
      if (o[c] == b && o[(c + 1) % 3] == a) return {t, u};
    }
  }
  return {t, t};
}

TEST(SurfaceRepair, CleanSurfaceIsUnchanged) {
  const TriangleMesh mesh = block_surface();
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  expect_clean(repaired);
  EXPECT_EQ(repaired.triangles.size(), mesh.triangles.size());
  EXPECT_EQ(point_set(repaired), point_set(mesh));
  EXPECT_EQ(counts.holes_filled + counts.degenerate_triangles_removed +
                counts.non_manifold_vertices_split + counts.needles_before + counts.caps_before,
            0u);
}

TEST(SurfaceRepair, HolesAreFilledWithoutMovingPoints) {
  TriangleMesh mesh = block_surface();
  const size_t triangles = mesh.triangles.size();
  // Two holes far apart: the first triangle and the last one.
  mesh.triangles.erase(mesh.triangles.end() - 1);
  mesh.triangles.erase(mesh.triangles.begin());
  ASSERT_EQ(compute_surface_statistics(mesh).boundary_edges, 6u);
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  EXPECT_EQ(counts.holes_filled, 2u);
  expect_clean(repaired);
  EXPECT_EQ(repaired.triangles.size(), triangles);
  EXPECT_EQ(point_set(repaired), point_set(mesh));
}

TEST(SurfaceRepair, NonManifoldVertexIsSplit) {
  // Two tetrahedra sharing only their apex.
  TriangleMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                    {0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}};
  ASSERT_EQ(compute_surface_statistics(mesh).non_manifold_vertices, 1u);
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  EXPECT_EQ(counts.non_manifold_vertices_split, 1u);
  expect_clean(repaired);
  EXPECT_EQ(repaired.points.size(), 8u);
  EXPECT_EQ(compute_surface_statistics(repaired).components, 2u);
  EXPECT_EQ(point_set(repaired), point_set(mesh));
}

// The block with the first edge of triangle 0 split `fraction` of the way
// along: needles for small fractions.
TriangleMesh block_with_split_edge(double fraction) {
  TriangleMesh mesh = block_surface();
  const auto [t, u] = triangles_on_edge(mesh, 0);
  const uint32_t a = mesh.triangles[t][0], b = mesh.triangles[t][1], c = mesh.triangles[t][2];
  const uint32_t d = mesh.triangles[u][0] + mesh.triangles[u][1] + mesh.triangles[u][2] - a - b;
  const auto m = static_cast<uint32_t>(mesh.points.size());
  const auto &pa = mesh.points[a], &pb = mesh.points[b];
  mesh.points.push_back({pa[0] + fraction * (pb[0] - pa[0]), pa[1] + fraction * (pb[1] - pa[1]),
                         pa[2] + fraction * (pb[2] - pa[2])});
  mesh.triangles[t] = {a, m, c};
  mesh.triangles[u] = {b, m, d};
  mesh.triangles.push_back({m, b, c});
  mesh.triangles.push_back({m, a, d});
  return mesh;
}

// The block with a point inside triangle 0, `depth` of the way from the
// middle of its first edge to its third corner: a cap for small depths.
TriangleMesh block_with_inner_point(double depth) {
  TriangleMesh mesh = block_surface();
  const uint32_t a = mesh.triangles[0][0], b = mesh.triangles[0][1], c = mesh.triangles[0][2];
  const auto &pa = mesh.points[a], &pb = mesh.points[b], &pc = mesh.points[c];
  Point m{};
  for (int i = 0; i < 3; ++i) m[i] = (1 - depth) / 2 * (pa[i] + pb[i]) + depth * pc[i];
  const auto mi = static_cast<uint32_t>(mesh.points.size());
  mesh.points.push_back(m);
  mesh.triangles[0] = {a, b, mi};
  mesh.triangles.push_back({b, c, mi});
  mesh.triangles.push_back({c, a, mi});
  return mesh;
}

TEST(SurfaceRepair, NeedlesAreCollapsed) {
  const auto original = point_set(block_surface());
  // An edge split 2 % of the way along: two needles.
  const TriangleMesh mesh = block_with_split_edge(0.02);
  ASSERT_TRUE(compute_surface_statistics(mesh).closed);
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  EXPECT_EQ(counts.needles_before, 2u);
  EXPECT_EQ(counts.needles_after, 0u);
  expect_clean(repaired);
  // The collapse keeps one end of the short edge: every other point is where it was.
  EXPECT_EQ(repaired.points.size(), original.size());
  size_t unmoved = 0;
  for (const auto& p : repaired.points) unmoved += original.count(p);
  EXPECT_GE(unmoved, original.size() - 1);
}

TEST(SurfaceRepair, CapIsRemoved) {
  const auto original = point_set(block_surface());
  // A point just inside a triangle, by the middle of its first edge: an
  // angle of almost 180 degrees there.
  const TriangleMesh mesh = block_with_inner_point(0.02);
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  EXPECT_EQ(counts.caps_before, 1u);
  EXPECT_EQ(counts.caps_after + counts.needles_after, 0u);
  expect_clean(repaired);
  size_t unmoved = 0;
  for (const auto& p : repaired.points) unmoved += original.count(p);
  EXPECT_GE(unmoved, original.size() - 1);
}

// Needles and caps as CGAL's own predicates count them, face by face.
uint32_t sharp_by_cgal(const TriangleMesh& triangles) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  const auto mesh = cgal::to_surface_mesh(triangles);
  EXPECT_TRUE(mesh.has_value());
  if (!mesh) return 0;
  const RepairParams params;
  const double cap_cosine = std::cos(params.cap_angle_deg * M_PI / 180);
  uint32_t sharp = 0;
  for (auto f : mesh->faces()) {
    sharp += PMP::is_needle_triangle_face(f, *mesh, params.needle_ratio) !=
                 cgal::Mesh::null_halfedge() ||
             PMP::is_cap_triangle_face(f, *mesh, cap_cosine) != cgal::Mesh::null_halfedge();
  }
  return sharp;
}

// Scans `shape` over [low, high], finds by bisection each parameter where
// CGAL's count of sharp faces changes, and checks the repair's count at, and
// a few units in the last place either side of, every such threshold (where
// a fast inexact test could misjudge a face), and along the scan.
void expect_sharp_counts_match_cgal(const std::function<TriangleMesh(double)>& shape, double low,
                                    double high) {
  auto repair_count = [&](double x) {
    RepairCounts counts;
    repair(shape(x), counts);
    return counts.needles_before + counts.caps_before;
  };
  auto cgal_count = [&](double x) { return sharp_by_cgal(shape(x)); };
  constexpr int kSteps = 60;
  int thresholds = 0;
  for (int i = 0; i < kSteps; ++i) {
    double x0 = low + (high - low) * i / kSteps, x1 = low + (high - low) * (i + 1) / kSteps;
    const uint32_t at_x0 = cgal_count(x0);
    EXPECT_EQ(repair_count(x0), at_x0) << "at " << x0;
    if (cgal_count(x1) == at_x0) continue;
    ++thresholds;
    while (std::nextafter(x0, x1) < x1) {
      const double middle = x0 + (x1 - x0) / 2;
      if (middle <= x0 || middle >= x1) break;
      (cgal_count(middle) == at_x0 ? x0 : x1) = middle;
    }
    double x = x0;
    for (int ulp = 0; ulp < 4; ++ulp) x = std::nextafter(x, low);
    for (int ulp = 0; ulp < 9; ++ulp, x = std::nextafter(x, high))
      EXPECT_EQ(repair_count(x), cgal_count(x)) << "at " << x;
  }
  EXPECT_GE(thresholds, 1) << "the scan must cross a threshold";
}

TEST(SurfaceRepair, SharpCountsMatchCgalAtTheThresholds) {
  expect_sharp_counts_match_cgal(block_with_split_edge, 0.01, 0.5);
  expect_sharp_counts_match_cgal(block_with_inner_point, 0.001, 0.2);
}

TEST(SurfaceRepair, DegenerateTrianglesAreRemoved) {
  TriangleMesh mesh = block_surface();
  const size_t triangles = mesh.triangles.size();
  mesh.triangles.push_back({0, 0, 1});  // repeated corner
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  EXPECT_EQ(counts.degenerate_triangles_removed, 1u);
  expect_clean(repaired);
  EXPECT_EQ(repaired.triangles.size(), triangles);
}

TEST(SurfaceRepair, InwardSurfaceIsTurnedOutward) {
  TriangleMesh mesh = block_surface();
  mesh.flip_orientation();
  RepairCounts counts;
  const TriangleMesh repaired = repair(mesh, counts);
  expect_clean(repaired);
}

}  // namespace
}  // namespace labelmesh::surface
