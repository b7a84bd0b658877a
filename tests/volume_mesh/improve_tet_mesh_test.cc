// SPDX-License-Identifier: AGPL-3.0-or-later
// The improvement pass on meshes built to need one operation each: a 3-2 flip,
// a 2-3 flip, smoothing of an interior point, peeling a sliver off the
// surface; and that otherwise the boundary and the region never change.
#include "core/volume_mesh/improve_tet_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/quality/element_quality.h"
#include "support/status_matchers.h"

namespace labelmesh::volume_mesh {
namespace {

double total_volume(const TetMesh& m) {
  double sum = 0;
  for (size_t t = 0; t < m.tetrahedra.size(); ++t) sum += signed_volume(m, t);
  return sum;
}

// Appends tetrahedron `t` with `label`, its first two points swapped if
// needed so that it is positive (VTK ordering).
void add_positive(TetMesh& m, std::array<uint32_t, 4> t, int32_t label) {
  if (quality::tetra_signed_volume(
          {m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]}) < 0)
    std::swap(t[0], t[1]);
  m.tetrahedra.push_back(t);
  m.labels.push_back(label);
}

double lowest_quality(const TetMesh& m) {
  double lowest = 1e9;
  for (const auto& t : m.tetrahedra) {
    lowest = std::min(lowest, quality::tetra_quality({m.points[t[0]], m.points[t[1]],
                                                      m.points[t[2]], m.points[t[3]]}));
  }
  return lowest;
}

// Three tetrahedra around the edge a-b of a bipyramid whose two halves
// (apexes a and b over triangle c,d,e) are regular tetrahedra.
TetMesh bipyramid_as_three() {
  const double h = std::sqrt(2.0 / 3.0);
  const double r = 1 / std::sqrt(3.0);
  TetMesh m;
  m.points = {{0, 0, h},
              {0, 0, -h},
              {r, 0, 0},
              {r * std::cos(2.0943951023931953), r * std::sin(2.0943951023931953), 0},
              {r * std::cos(4.1887902047863905), r * std::sin(4.1887902047863905), 0}};
  // a=0, b=1, c=2, d=3, e=4; tetrahedra a,b with each edge of c,d,e.
  for (const auto& [x, y] : {std::pair{2u, 3u}, {3u, 4u}, {4u, 2u}}) {
    add_positive(m, {x, y, 1, 0}, 4);
  }
  return m;
}

TEST(ImproveTetMesh, ThreeAroundAnEdgeBecomeTwoRegularTetrahedra) {
  TetMesh m = bipyramid_as_three();
  const double volume = total_volume(m);
  const double before = lowest_quality(m);
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {.target_quality = 0.9}, RunContext{}, figures), testing::IsOk());
  EXPECT_EQ(figures.flips_3_2, 1u);
  ASSERT_EQ(m.tetrahedra.size(), 2u);
  EXPECT_NEAR(lowest_quality(m), 1.0, 1e-12);
  EXPECT_LT(before, 0.7);
  EXPECT_NEAR(figures.quality_min_before, before, 1e-12);
  EXPECT_NEAR(figures.quality_min_after, 1.0, 1e-12);
  EXPECT_NEAR(total_volume(m), volume, 1e-12);
  EXPECT_EQ(m.labels, (std::vector<int32_t>{4, 4}));
  EXPECT_EQ(m.points.size(), 5u);
}

TEST(ImproveTetMesh, TwoFlatTetrahedraBecomeThree) {
  // Triangle c,d,e with apexes just above and below: two flat tetrahedra,
  // which the three around the new edge a-b beat.
  TetMesh m = bipyramid_as_three();
  m.points[0][2] = 0.15;
  m.points[1][2] = -0.15;
  m.tetrahedra = {{2, 3, 4, 0}, {3, 2, 4, 1}};
  m.labels = {1, 1};
  ASSERT_GT(signed_volume(m, 0), 0);
  ASSERT_GT(signed_volume(m, 1), 0);
  const double volume = total_volume(m);
  const double before = lowest_quality(m);
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {.target_quality = 0.9}, RunContext{}, figures), testing::IsOk());
  EXPECT_EQ(figures.flips_2_3, 1u);
  EXPECT_EQ(m.tetrahedra.size(), 3u);
  EXPECT_GT(lowest_quality(m), before + 0.1);
  EXPECT_NEAR(total_volume(m), volume, 1e-12);
}

// A cube of 2x2x2 cells, each cut into six tetrahedra around its diagonal,
// with the one interior point (the centre) pushed near a corner.
TetMesh cube_with_displaced_centre() {
  TetMesh m;
  for (int z = 0; z <= 2; ++z)
    for (int y = 0; y <= 2; ++y)
      for (int x = 0; x <= 2; ++x) m.points.push_back({double(x), double(y), double(z)});
  auto id = [](int x, int y, int z) { return uint32_t(x + 3 * y + 9 * z); };
  // Freudenthal: the six paths from corner 0 to corner 7 of each cell.
  const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x)
        for (const auto& path : paths) {
          int c[3] = {x, y, z};
          std::array<uint32_t, 4> t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[path[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          add_positive(m, t, 2);
        }
  m.points[id(1, 1, 1)] = {0.3, 0.35, 0.4};
  return m;
}

TEST(ImproveTetMesh, SmoothingLiftsTheWorstElementAndKeepsTheBoundary) {
  TetMesh m = cube_with_displaced_centre();
  const auto boundary_before = m.points;
  const double before = lowest_quality(m);
  ASSERT_GT(before, 0);
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {}, RunContext{}, figures), testing::IsOk());
  EXPECT_GT(figures.vertices_moved, 0u);
  EXPECT_GT(lowest_quality(m), 0.5);
  EXPECT_GT(lowest_quality(m), before + 0.3);
  EXPECT_NEAR(total_volume(m), 8.0, 1e-9);
  for (size_t t = 0; t < m.tetrahedra.size(); ++t) EXPECT_GT(signed_volume(m, t), 0);
  // Every point but the centre is on the cube's surface and stays put.
  for (uint32_t v = 0; v < boundary_before.size(); ++v) {
    if (v != 13u) {
      EXPECT_EQ(m.points[v], boundary_before[v]) << "point " << v;
    }
  }
}

// A flat sliver a,b,c,d of label 3: its faces a,b,c and a,b,d are the
// surface, a low roof over the edge c-d. Below, tetrahedra b,e,c,d (label
// 3), e,f,c,d (label 4) and f,a,c,d (label 3) close the ring around c-d.
// Label 3 wraps 300 degrees around c-d, so a point inserted in it has to sit
// under the low roof, and no point insertion lifts the sliver.
TetMesh roof_sliver(double height) {
  TetMesh m;
  m.points = {{1, -1, height}, {1, 1, height},  {0, 0, 0},
              {2, 0, 0},       {1, 0.75, -1.3}, {1, -0.75, -1.3}};
  const uint32_t a = 0, b = 1, c = 2, d = 3, e = 4, f = 5;
  add_positive(m, {a, b, c, d}, 3);
  add_positive(m, {b, e, c, d}, 3);
  add_positive(m, {e, f, c, d}, 4);
  add_positive(m, {f, a, c, d}, 3);
  return m;
}

TEST(ImproveTetMesh, ASliverUnderTheSurfaceIsPeeledWithinTheDepthBound) {
  TetMesh m = roof_sliver(0.1);
  const double volume = total_volume(m);
  const double sliver_volume = signed_volume(m, 0);
  ASSERT_LT(lowest_quality(m), 0.2);
  ImproveFigures figures;
  // Deeper than the bound: the sliver stays.
  ASSERT_THAT(improve_tet_mesh(m, {.max_peel_depth_mm = 0.05}, RunContext{}, figures),
              testing::IsOk());
  EXPECT_EQ(figures.slivers_peeled, 0u);
  EXPECT_LT(lowest_quality(m), 0.2);
  EXPECT_EQ(m.tetrahedra.size(), 4u);

  m = roof_sliver(0.1);
  ASSERT_THAT(improve_tet_mesh(m, {.max_peel_depth_mm = 0.2}, RunContext{}, figures),
              testing::IsOk());
  EXPECT_EQ(figures.slivers_peeled, 1u);
  EXPECT_EQ(m.tetrahedra.size(), 3u);
  EXPECT_GT(lowest_quality(m), 0.2);
  // The sliver is 0.1 thick between its edges a-b and c-d.
  EXPECT_NEAR(figures.peel_depth_mm, 0.1, 1e-12);
  EXPECT_NEAR(figures.peeled_volume_mm3, sliver_volume, 1e-12);
  EXPECT_NEAR(total_volume(m), volume - sliver_volume, 1e-12);
  EXPECT_EQ(m.points.size(), 6u);
  EXPECT_EQ(m.labels, (std::vector<int32_t>{3, 4, 3}));
  EXPECT_THAT(check_tet_mesh(m), testing::IsOk());
}

TEST(ImproveTetMesh, ASliverBorderingAnotherLabelIsNotPeeled) {
  TetMesh m = roof_sliver(0.1);
  m.labels[1] = 5;  // b,e,c,d: the sliver's face b,c,d is now an interface
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {.max_peel_depth_mm = 0.2}, RunContext{}, figures),
              testing::IsOk());
  EXPECT_EQ(figures.slivers_peeled, 0u);
  EXPECT_NEAR(total_volume(m), total_volume(roof_sliver(0.1)), 1e-12);
}

TEST(ImproveTetMesh, ASliverWhoseOtherEdgeIsOnTheSurfaceIsNotPeeled) {
  // Without e,f,c,d the faces e,c,d and f,c,d are surface too: peeling would
  // leave four surface triangles on the edge c-d.
  TetMesh m = roof_sliver(0.1);
  m.tetrahedra.erase(m.tetrahedra.begin() + 2);
  m.labels.erase(m.labels.begin() + 2);
  const double volume = total_volume(m);
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {.max_peel_depth_mm = 0.2}, RunContext{}, figures),
              testing::IsOk());
  EXPECT_EQ(figures.slivers_peeled, 0u);
  EXPECT_NEAR(total_volume(m), volume, 1e-12);
}

TEST(ImproveTetMesh, AGoodMeshIsLeftAlone) {
  TetMesh m = cube_with_displaced_centre();
  m.points[13] = {1, 1, 1};
  const TetMesh before = m;
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {.target_quality = 0.5}, RunContext{}, figures), testing::IsOk());
  EXPECT_EQ(m.tetrahedra, before.tetrahedra);
  EXPECT_EQ(m.points, before.points);
  EXPECT_EQ(figures.sweeps, 0);
}

TEST(ImproveTetMesh, AStopRequestEndsThePassWithAValidMesh) {
  TetMesh m = cube_with_displaced_centre();
  std::atomic<bool> stop{true};
  RunContext context;
  context.stop = &stop;
  ImproveFigures figures;
  EXPECT_EQ(improve_tet_mesh(m, {}, context, figures).code(), absl::StatusCode::kCancelled);
  EXPECT_NEAR(total_volume(m), 8.0, 1e-9);
  for (size_t t = 0; t < m.tetrahedra.size(); ++t) EXPECT_GT(signed_volume(m, t), 0);
}

// An interior point inside a tetrahedron A,B,C,D that is symmetric across
// the plane x = 0, at the centroid of A,B,C,D (so the move to its
// neighbours' centroid goes nowhere). Its two worst tetrahedra, v,A,C,D and
// v,B,C,D, are mirror images tied at Q 0.151: the gradient of either one
// points mostly across the mirror, into the other, so climbing it lowers the
// twin and the star's minimum never rises. The sum of their unit gradients
// lies in the mirror plane and lifts both (with the worst one's gradient
// alone, the pass leaves Q at 0.151).
TEST(ImproveTetMesh, SmoothingClimbsBetweenTwoTiedWorstTetrahedra) {
  const double a = 0.587, b = 1.67, b2 = 1.221, c1 = -0.512, c2 = -0.906;
  TetMesh m;
  m.points = {{-a, 0, 0}, {a, 0, 0}, {0, b, c1}, {0, -b2, c2}, {0, (b - b2) / 4, (c1 + c2) / 4}};
  for (uint32_t corner = 0; corner < 4; ++corner) {
    std::array<uint32_t, 4> t = {0, 1, 2, 3};
    t[corner] = 4;
    add_positive(m, t, 1);
  }
  const double volume = total_volume(m);
  ASSERT_NEAR(lowest_quality(m), 0.151, 0.001);
  ImproveFigures figures;
  ASSERT_THAT(improve_tet_mesh(m, {}, RunContext{}, figures), testing::IsOk());
  EXPECT_GE(figures.vertices_moved + figures.vertices_inserted, 1u);
  EXPECT_GT(lowest_quality(m), 0.19);
  EXPECT_THAT(check_tet_mesh(m), testing::IsOk());
  EXPECT_EQ(m.tetrahedra.size(), 4u);
  EXPECT_NEAR(total_volume(m), volume, 1e-12);
  // One interior point, whichever operation placed it last: a point an
  // insertion replaced is not left behind as a node of no element.
  EXPECT_EQ(m.points.size(), 5u);
  std::vector<int> uses(m.points.size(), 0);
  for (const auto& t : m.tetrahedra)
    for (uint32_t v : t) ++uses[v];
  for (int count : uses) EXPECT_GT(count, 0);
  // The outer points stay put.
  EXPECT_EQ(m.points[0], (std::array<double, 3>{-a, 0, 0}));
  EXPECT_EQ(m.points[3], (std::array<double, 3>{0, -b2, c2}));
}

}  // namespace
}  // namespace labelmesh::volume_mesh
