// SPDX-License-Identifier: AGPL-3.0-or-later
// TetGen meshes of hand-built closed surfaces, checked against invariants: the tetrahedra fill
// exactly the enclosed volume, all are positive, and with keep_boundary the mesh's boundary is
// the input surface, triangle for triangle and with the same winding.
#include "core/volume_mesh/tetrahedralize.h"
#include "support/status_matchers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

namespace labelmesh::volume_mesh {
namespace {

using Point = std::array<double, 3>;
using surface::TriangleMesh;

// An axis-aligned cube [lo, lo + size]³, wound outwards (or inwards when `inward`).
TriangleMesh cube(Point lo, double size, bool inward = false) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.points.push_back(
        {lo[0] + (i & 1 ? size : 0), lo[1] + (i & 2 ? size : 0), lo[2] + (i & 4 ? size : 0)});
  }
  // Quads counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  if (inward) mesh.flip_orientation();
  return mesh;
}

// An icosahedron subdivided `levels` times, projected onto a sphere; outward.
TriangleMesh icosphere(double radius, int levels) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh mesh;
  mesh.points = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                 {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    const auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      const auto& p = mesh.points[a];
      const auto& q = mesh.points[b];
      mesh.points.push_back({(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2});
      const auto index = uint32_t(mesh.points.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<std::array<uint32_t, 3>> finer;
    for (const auto& t : mesh.triangles) {
      const uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]),
                     ca = midpoint(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(finer);
  }
  for (auto& p : mesh.points) {
    const double scale = radius / std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (double& c : p) c *= scale;
  }
  return mesh;
}

TriangleMesh combined(std::initializer_list<TriangleMesh> pieces) {
  TriangleMesh mesh;
  for (const auto& piece : pieces) mesh.append(piece);
  return mesh;
}

double enclosed_volume(const TriangleMesh& mesh) {
  double sum = 0;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.points[t[0]];
    const auto& b = mesh.points[t[1]];
    const auto& c = mesh.points[t[2]];
    sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return sum / 6;
}

double tet_volume(const TetMesh& mesh, const std::array<uint32_t, 4>& t) {
  const auto& p0 = mesh.points[t[0]];
  double e[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) e[i][k] = mesh.points[t[i + 1]][k] - p0[k];
  }
  return (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
         6;
}

// A triangle by its corners' coordinates, rotated so the smallest corner comes first: equal for
// the same triangle with the same winding, whatever the point numbering.
using OrientedTriangle = std::array<Point, 3>;
OrientedTriangle oriented(Point a, Point b, Point c) {
  std::array<Point, 3> t{a, b, c};
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

// The mesh's boundary: the faces only one tetrahedron has, wound out of that tetrahedron.
std::multiset<OrientedTriangle> mesh_boundary(const TetMesh& mesh) {
  // With node 3 on the positive side of face 0,1,2, these windings point away from the
  // omitted node.
  const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<uint32_t, 3>, std::vector<OrientedTriangle>> by_key;
  for (const auto& t : mesh.tetrahedra) {
    for (const auto& f : faces) {
      std::array<uint32_t, 3> key{t[f[0]], t[f[1]], t[f[2]]};
      std::sort(key.begin(), key.end());
      by_key[key].push_back(
          oriented(mesh.points[t[f[0]]], mesh.points[t[f[1]]], mesh.points[t[f[2]]]));
    }
  }
  std::multiset<OrientedTriangle> boundary;
  for (const auto& [key, sides] : by_key) {
    EXPECT_LE(sides.size(), 2u) << "a face shared by more than two tetrahedra";
    if (sides.size() == 1) boundary.insert(sides[0]);
  }
  return boundary;
}

std::multiset<OrientedTriangle> surface_triangles(const TriangleMesh& mesh) {
  std::multiset<OrientedTriangle> triangles;
  for (const auto& t : mesh.triangles)
    triangles.insert(oriented(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]));
  return triangles;
}

// The invariants every result must meet; returns the summed tetrahedron volume.
double check_mesh(const TetMesh& mesh, int32_t label, const TetgenFigures& figures) {
  EXPECT_FALSE(mesh.tetrahedra.empty());
  EXPECT_EQ(mesh.labels.size(), mesh.tetrahedra.size());
  for (int32_t l : mesh.labels) EXPECT_EQ(l, label);
  double total = 0;
  size_t non_positive = 0;
  for (const auto& t : mesh.tetrahedra) {
    for (uint32_t v : t) EXPECT_LT(v, mesh.points.size());
    const double volume = tet_volume(mesh, t);
    non_positive += !(volume > 0);
    total += volume;
  }
  EXPECT_EQ(non_positive, 0u);
  EXPECT_EQ(figures.tetrahedra, mesh.tetrahedra.size());
  EXPECT_EQ(figures.input_points + figures.steiner_points, mesh.points.size());
  EXPECT_GE(figures.seconds, 0.0);
  return total;
}

TEST(Tetrahedralize, CubeFillsItsVolumeAndKeepsItsTriangles) {
  const TriangleMesh surface = cube({0, 0, 0}, 10);
  ASSERT_DOUBLE_EQ(enclosed_volume(surface), 1000);
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 7, TetgenParams{}, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 7, figures), 1000, 1e-9 * 1000);
  EXPECT_EQ(figures.input_points, 8u);
  EXPECT_EQ(figures.input_triangles, 12u);
  EXPECT_GE(mesh->tetrahedra.size(), 5u);
  EXPECT_EQ(mesh_boundary(*mesh), surface_triangles(surface));
}

TEST(Tetrahedralize, IcosphereFillsItsVolumeAndKeepsItsTriangles) {
  const TriangleMesh surface = icosphere(10, 2);
  ASSERT_EQ(surface.points.size(), 162u);
  ASSERT_EQ(surface.triangles.size(), 320u);
  const double volume = enclosed_volume(surface);
  // Inscribed in the sphere, and close to it.
  ASSERT_GT(volume, 0.9 * 4.0 / 3.0 * std::numbers::pi * 1000);
  ASSERT_LT(volume, 4.0 / 3.0 * std::numbers::pi * 1000);
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 1, TetgenParams{}, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 1, figures), volume, 1e-9 * volume);
  EXPECT_EQ(figures.input_points, 162u);
  EXPECT_EQ(figures.input_triangles, 320u);
  EXPECT_EQ(mesh_boundary(*mesh), surface_triangles(surface));
  // Input points keep their coordinates exactly.
  std::set<Point> points(mesh->points.begin(), mesh->points.end());
  for (const auto& p : surface.points) EXPECT_TRUE(points.count(p)) << p[0] << " " << p[1];
}

TEST(Tetrahedralize, VolumeBoundRefinesAndMayMoveTheBoundary) {
  const TriangleMesh surface = icosphere(10, 2);
  const double volume = enclosed_volume(surface);
  TetgenParams params;
  params.max_volume_mm3 = 5;
  params.keep_boundary = false;
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 1, params, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 1, figures), volume, 1e-9 * volume);
  EXPECT_GT(figures.steiner_points, 0u);
  // At least volume / bound tetrahedra. Refinement keeps every tetrahedron
  // under the bound; TetGen's optimisation afterwards (-o/, flips that merge
  // neighbours) may exceed it a little: measured 5.11 here.
  EXPECT_GE(mesh->tetrahedra.size(), size_t(volume / 5));
  double largest = 0;
  for (const auto& t : mesh->tetrahedra) largest = std::max(largest, tet_volume(*mesh, t));
  EXPECT_LE(largest, 5 * 1.05);
}

TEST(Tetrahedralize, InnerShellWoundInwardsIsACavity) {
  const TriangleMesh surface = combined({cube({0, 0, 0}, 10), cube({3, 3, 3}, 4, true)});
  ASSERT_DOUBLE_EQ(enclosed_volume(surface), 1000 - 64);
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 2, TetgenParams{}, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 2, figures), 936, 1e-9 * 936);
  EXPECT_EQ(mesh_boundary(*mesh), surface_triangles(surface));
  for (const auto& t : mesh->tetrahedra) {
    Point c{0, 0, 0};
    for (uint32_t v : t) {
      for (int k = 0; k < 3; ++k) c[k] += mesh->points[v][k] / 4;
    }
    const bool in_cavity = c[0] > 3 && c[0] < 7 && c[1] > 3 && c[1] < 7 && c[2] > 3 && c[2] < 7;
    EXPECT_FALSE(in_cavity) << c[0] << " " << c[1] << " " << c[2];
  }
}

TEST(Tetrahedralize, IslandInsideACavityIsMaterial) {
  const TriangleMesh surface =
      combined({cube({0, 0, 0}, 30), cube({5, 5, 5}, 20, true), cube({10, 10, 10}, 10)});
  const double expected = 27000 - 8000 + 1000;
  ASSERT_DOUBLE_EQ(enclosed_volume(surface), expected);
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 3, TetgenParams{}, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 3, figures), expected, 1e-9 * expected);
  EXPECT_EQ(mesh_boundary(*mesh), surface_triangles(surface));
}

TEST(Tetrahedralize, SeparateBodiesAreBothMeshed) {
  const TriangleMesh surface = combined({cube({0, 0, 0}, 10), cube({20, 0, 0}, 5)});
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 4, TetgenParams{}, RunContext{}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  EXPECT_NEAR(check_mesh(*mesh, 4, figures), 1125, 1e-9 * 1125);
  EXPECT_EQ(mesh_boundary(*mesh), surface_triangles(surface));
}

TEST(Tetrahedralize, OutOfRangeParametersNameTheOption) {
  const TriangleMesh surface = cube({0, 0, 0}, 10);
  struct Case {
    TetgenParams params;
    std::string option;
  };
  std::vector<Case> cases;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double ratio : {0.9, 0.0, -1.0, 101.0, nan}) {
    cases.push_back({TetgenParams{.radius_edge_ratio = ratio}, "tet_radius_edge"});
  }
  for (double angle : {-1.0, 31.0, 70.0, nan}) {
    cases.push_back({TetgenParams{.min_dihedral_deg = angle}, "tet_min_dihedral_deg"});
  }
  for (double volume : {-1.0, 1e-9, 1e13, std::numeric_limits<double>::infinity(), nan}) {
    cases.push_back({TetgenParams{.max_volume_mm3 = volume}, "tet_max_volume_mm3"});
  }
  for (const auto& c : cases) {
    TetgenFigures figures;
    const auto mesh = tetrahedralize(surface, 1, c.params, RunContext{}, figures);
    ASSERT_FALSE(mesh.ok()) << c.option;
    EXPECT_THAT(mesh, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << mesh.status();
    EXPECT_EQ(std::string(mesh.status().message()).rfind(c.option + ": ", 0), 0u) << mesh.status();
  }
}

TEST(Tetrahedralize, TooSmallOrBrokenSurfacesAreInvalid) {
  TriangleMesh three_points;
  three_points.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  three_points.triangles = {{0, 1, 2}, {0, 2, 1}, {0, 1, 2}, {0, 2, 1}};
  TriangleMesh no_triangles = cube({0, 0, 0}, 1);
  no_triangles.triangles.clear();
  TriangleMesh bad_index = cube({0, 0, 0}, 1);
  bad_index.triangles[3][1] = 8;
  TriangleMesh repeated_corner = cube({0, 0, 0}, 1);
  repeated_corner.triangles[0] = {1, 1, 2};
  for (const auto* surface : {&three_points, &no_triangles, &bad_index, &repeated_corner}) {
    TetgenFigures figures;
    const auto mesh = tetrahedralize(*surface, 5, TetgenParams{}, RunContext{}, figures);
    ASSERT_FALSE(mesh.ok());
    EXPECT_THAT(mesh, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << mesh.status();
    EXPECT_NE(std::string(mesh.status().message()).find("label 5"), std::string::npos)
        << mesh.status();
  }
}

TEST(Tetrahedralize, SelfIntersectingSurfaceIsAnErrorNotACrash) {
  const TriangleMesh surface = combined({cube({0, 0, 0}, 10), cube({5, 5, 5}, 10)});
  TetgenFigures figures;
  const auto mesh = tetrahedralize(surface, 9, TetgenParams{}, RunContext{}, figures);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh, testing::StatusIs(absl::StatusCode::kFailedPrecondition)) << mesh.status();
  EXPECT_NE(std::string(mesh.status().message()).find("label 9 intersects itself"),
            std::string::npos)
      << mesh.status();
  EXPECT_EQ(figures.input_triangles, 24u);
  EXPECT_EQ(figures.tetrahedra, 0u);
}

TEST(Tetrahedralize, InwardSurfaceIsRefused) {
  TetgenFigures figures;
  const auto single =
      tetrahedralize(cube({0, 0, 0}, 10, true), 6, TetgenParams{}, RunContext{}, figures);
  ASSERT_FALSE(single.ok());
  EXPECT_THAT(single, testing::StatusIs(absl::StatusCode::kFailedPrecondition)) << single.status();
  // An inward outer shell around an outward inner one encloses a negative volume.
  const auto nested = tetrahedralize(combined({cube({0, 0, 0}, 10, true), cube({3, 3, 3}, 4)}), 6,
                                     TetgenParams{}, RunContext{}, figures);
  ASSERT_FALSE(nested.ok());
  EXPECT_THAT(nested, testing::StatusIs(absl::StatusCode::kFailedPrecondition)) << nested.status();
}

TEST(Tetrahedralize, StopRequestCancelsAndProgressReachesOne) {
  const TriangleMesh surface = cube({0, 0, 0}, 10);
  std::atomic<bool> stop{true};
  RunContext stopped;
  stopped.stop = &stop;
  TetgenFigures figures;
  const auto cancelled = tetrahedralize(surface, 1, TetgenParams{}, stopped, figures);
  ASSERT_FALSE(cancelled.ok());
  EXPECT_THAT(cancelled, testing::StatusIs(absl::StatusCode::kCancelled));

  std::vector<double> fractions;
  RunContext watched;
  watched.progress = [&](const ProgressUpdate& update) {
    EXPECT_EQ(update.stage, "tetgen");
    fractions.push_back(update.fraction);
  };
  ASSERT_THAT(tetrahedralize(surface, 1, TetgenParams{}, watched, figures), testing::IsOk());
  ASSERT_GE(fractions.size(), 2u);
  EXPECT_EQ(fractions.front(), 0.0);
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
}

}  // namespace
}  // namespace labelmesh::volume_mesh
