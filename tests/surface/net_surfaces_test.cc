// SPDX-License-Identifier: AGPL-3.0-or-later
// The default surfaces: labels cut from one shared surface net, closed and
// manifold each, sharing their interfaces, judged against the voxels; and
// the voxel figures the guard judges them by.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkShortArray.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "core/conforming/label_interfaces.h"
#include "core/conforming/net_label_surface.h"
#include "core/conforming/widen_small_angles.h"
#include "core/pipeline/label_net_surfaces.h"
#include "core/pipeline/pipeline.h"
#include "core/surface/crossing_triangles.h"
#include "core/surface/surface_checks.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/voxel_fidelity.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/phantom_grid.h"
#include "core/volume/read_label_volume.h"
#include "support/analytic_shapes.h"
#include "support/label_grid.h"
#include "support/label_overlap.h"
#include "support/label_volumes.h"
#include "support/mesh_results.h"
#include "support/organs_on_slices.h"
#include "support/slicer_like.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

using surface::TriangleMesh;

conforming::InterfaceSurface staircase_net(const volume::LabelVolume& volume) {
  conforming::InterfaceParams flat;
  flat.smoothing_rounds = 0;
  flat.subdivide_thick_quads = false;
  conforming::InterfaceFigures figures;
  return conforming::label_interfaces(volume, {}, flat, figures);
}

conforming::InterfaceSurface smoothed_net(const volume::LabelVolume& volume) {
  conforming::InterfaceFigures figures;
  return conforming::label_interfaces(volume, {}, net_interface_params(NetOptions{}), figures);
}

// Triangles of `a` whose three points are also a triangle of `b` (the same
// positions, any order).
size_t shared_triangles(const TriangleMesh& a, const TriangleMesh& b) {
  using Key = std::array<std::array<double, 3>, 3>;
  const auto key = [](const TriangleMesh& m, const std::array<uint32_t, 3>& t) {
    Key k{m.points[t[0]], m.points[t[1]], m.points[t[2]]};
    std::sort(k.begin(), k.end());
    return k;
  };
  std::map<Key, int> in_b;
  for (const auto& t : b.triangles) ++in_b[key(b, t)];
  size_t shared = 0;
  for (const auto& t : a.triangles) shared += in_b.count(key(a, t));
  return shared;
}

// Winding number of `mesh` around p (about 1 inside, 0 outside).
double winding_number(const TriangleMesh& mesh, const std::array<double, 3>& p) {
  double total = 0;
  for (const auto& t : mesh.triangles) {
    std::array<geometry::Vec3, 3> r;
    for (int k = 0; k < 3; ++k) r[k] = geometry::sub(mesh.points[t[k]], p);
    const double la = geometry::norm(r[0]), lb = geometry::norm(r[1]), lc = geometry::norm(r[2]);
    const double det = geometry::dot(r[0], geometry::cross(r[1], r[2]));
    const double div = la * lb * lc + geometry::dot(r[0], r[1]) * lc +
                       geometry::dot(r[1], r[2]) * la + geometry::dot(r[2], r[0]) * lb;
    total += 2 * std::atan2(det, div);
  }
  return total / (4 * M_PI);
}

TEST(NetLabelSurface, TouchingBoxesShareTheirInterfaceAndStayClosed) {
  // Box 1 is x 2..5, box 2 is x 6..8; both y and z 2..5: 16 voxel faces meet.
  const auto volume = testing::label_grid({11, 8, 8}, [](int i, int j, int k) -> uint8_t {
    if (j < 2 || j > 5 || k < 2 || k > 5) return 0;
    return i >= 2 && i <= 5 ? 1 : (i >= 6 && i <= 8 ? 2 : 0);
  });
  const auto net = smoothed_net(volume);
  const auto one = conforming::net_label_surface(net, 1, volume.geometry);
  const auto two = conforming::net_label_surface(net, 2, volume.geometry);
  for (const auto* s : {&one, &two}) {
    const auto statistics = surface::compute_surface_statistics(s->mesh);
    EXPECT_TRUE(statistics.closed);
    EXPECT_TRUE(statistics.manifold);
    EXPECT_GT(statistics.volume_mm3, 0);  // outward
    EXPECT_EQ(s->split_points, 0u);
    EXPECT_EQ(surface::count_self_intersections(s->mesh), uint64_t{0});
  }
  // The 16 shared faces, two triangles each, with the very same points.
  EXPECT_EQ(shared_triangles(one.mesh, two.mesh), 32u);
  // The staircase of box 1 encloses its 64 voxels exactly.
  EXPECT_NEAR(surface::signed_volume(one.staircase), 64.0, 1e-9);
}

TEST(NetLabelSurface, VoxelsTouchingAlongAnEdgeOrACornerStayManifold) {
  // Label 1: two voxels meeting along an edge; label 2: two meeting at a corner.
  const auto volume = testing::label_grid({10, 6, 6}, [](int i, int j, int k) -> uint8_t {
    if ((i == 1 && j == 1 && k == 2) || (i == 2 && j == 2 && k == 2)) return 1;
    if ((i == 6 && j == 1 && k == 1) || (i == 7 && j == 2 && k == 2)) return 2;
    return 0;
  });
  const auto net = smoothed_net(volume);
  for (int32_t label : {1, 2}) {
    const auto cut = conforming::net_label_surface(net, label, volume.geometry);
    const auto statistics = surface::compute_surface_statistics(cut.mesh);
    EXPECT_TRUE(statistics.closed) << label;
    EXPECT_TRUE(statistics.manifold) << label;
    EXPECT_EQ(statistics.components, 2u) << label;
    EXPECT_GT(cut.split_points, 0u) << label;
    EXPECT_EQ(surface::count_self_intersections(cut.mesh), uint64_t{0}) << label;
  }
}

TEST(NetLabelSurface, SplitCopiesWhoseSheetsCrossMoveFartherApart) {
  // Two columns of label 1, (1, 1, k) and (2, 2, k) for k = 1..6, meet along
  // the edge x = y = 1.5. Halfway up, one point of each column's face beside
  // the edge is pulled across the gap of outside between the two faces, as
  // smoothing can pinch two sheets that meet along an edge: the split copies,
  // a twentieth of the way towards their voxels, leave the faces crossing.
  const auto volume = testing::label_grid({5, 5, 8}, [](int i, int j, int k) -> uint8_t {
    return k >= 1 && k <= 6 && ((i == 1 && j == 1) || (i == 2 && j == 2)) ? 1 : 0;
  });
  auto net = staircase_net(volume);
  int pinched = 0;
  for (auto p = 0u; p < net.points.size(); ++p) {
    const auto& at = net.staircase[p];
    if (at[2] != 3.5) continue;
    if (at[0] == 1.5 && at[1] == 0.5) net.points[p][0] += 2.0, ++pinched;  // first column's
    if (at[0] == 2.5 && at[1] == 1.5) net.points[p][1] -= 0.6, ++pinched;  // second's
  }
  ASSERT_EQ(pinched, 2);
  const auto left =
      conforming::net_label_surface(net, 1, volume.geometry, conforming::SplitCrossings::kLeave);
  const auto parted = conforming::net_label_surface(net, 1, volume.geometry);
  ASSERT_GT(left.split_points, 0u);
  EXPECT_GT(surface::count_self_intersections(left.mesh).value_or(0), 0u);

  EXPECT_EQ(parted.split_crossings, 0u);
  EXPECT_EQ(surface::count_self_intersections(parted.mesh), uint64_t{0});
  const auto statistics = surface::compute_surface_statistics(parted.mesh);
  EXPECT_TRUE(statistics.closed);
  EXPECT_TRUE(statistics.manifold);
  // Only split copies moved farther, each a power of two as far from its net
  // point, at most 2^kSplitNudgeDoublings; the staircase stays where it was.
  ASSERT_EQ(parted.mesh.points.size(), left.mesh.points.size());
  int farther = 0;
  for (size_t p = 0; p < parted.mesh.points.size(); ++p) {
    EXPECT_EQ(parted.staircase.points[p], left.staircase.points[p]);
    if (parted.mesh.points[p] == left.mesh.points[p]) continue;
    ++farther;
    const auto net_point =
        std::find(net.staircase.begin(), net.staircase.end(), left.staircase.points[p]) -
        net.staircase.begin();
    const auto& from = net.points[static_cast<size_t>(net_point)];
    const double ratio = geometry::norm(geometry::sub(parted.mesh.points[p], from)) /
                         geometry::norm(geometry::sub(left.mesh.points[p], from));
    bool doubled = false;
    for (int k = 1; k <= conforming::kSplitNudgeDoublings; ++k)
      doubled |= std::abs(ratio - double(1 << k)) < 1e-9;
    EXPECT_TRUE(doubled) << ratio;
  }
  EXPECT_GT(farther, 0);
  EXPECT_LE(farther, static_cast<int>(parted.split_points));
}

TEST(VoxelFidelity, TheStaircaseIsExactAndAShrunkCopyIsNot) {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kSphere);
  const auto& v = phantom.volume;
  const auto statistics = volume::compute_label_statistics(v);
  const auto cut = conforming::net_label_surface(staircase_net(v), 1, v.geometry);
  auto exact = surface::measure_voxel_fidelity(cut.staircase, v, statistics.labels.front(), {});
  ASSERT_THAT(exact, testing::IsOk());
  EXPECT_NEAR(exact->volume_change, 0, 1e-9);
  EXPECT_EQ(exact->misclassified, 0u);
  EXPECT_GT(exact->boundary_voxels, 1000u);
  EXPECT_EQ(surface::corresponding_hausdorff_voxels(cut.staircase, cut.staircase, v.geometry), 0);
  // A sphere of radius 20 voxels whose surface moves in by a whole voxel:
  // every boundary voxel's centre falls outside it.
  TriangleMesh shrunk = cut.staircase;
  for (auto& p : shrunk.points)
    for (int k = 0; k < 3; ++k)
      p[k] = phantom.centre[k] + (p[k] - phantom.centre[k]) * (19.5 / 20.5);
  auto wrong = surface::measure_voxel_fidelity(shrunk, v, statistics.labels.front(), {});
  ASSERT_THAT(wrong, testing::IsOk());
  EXPECT_LT(wrong->volume_change, -0.1);
  EXPECT_GT(wrong->misclassified_fraction(), 0.5);
  EXPECT_GT(wrong->farthest_misclassified_voxels, 0.3);
  EXPECT_GT(surface::sampled_hausdorff_voxels(shrunk, cut.staircase, v.geometry, {}), 0.9);
}

TEST(VoxelFidelity, AxisAlignedShareOfAStaircaseAndOfABall) {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kSphere);
  const auto& v = phantom.volume;
  const auto cut = conforming::net_label_surface(staircase_net(v), 1, v.geometry);
  EXPECT_DOUBLE_EQ(surface::axis_aligned_share(cut.staircase, v.geometry), 1.0);
  const auto net = conforming::net_label_surface(smoothed_net(v), 1, v.geometry);
  EXPECT_LT(surface::axis_aligned_share(net.mesh, v.geometry), 0.15);
}

using testing::output_of;

// Label 1 of `v` by our default pipeline and by the Slicer-like one.
struct BothSurfaces {
  absl::StatusOr<MeshResult> result;
  std::vector<surface::LabelSurface> slicer;
  const SurfaceResult* ours() const { return result.ok() ? output_of(*result, 1) : nullptr; }
};

BothSurfaces both_surfaces(const volume::LabelVolume& v) {
  BothSurfaces both;
  both.slicer = testing::slicer_like_surfaces(v, volume::compute_label_statistics(v), {1});
  both.result = run_pipeline_on_volume(v, MeshParams{}, {});
  return both;
}

// A rod three voxels across shrinks under smoothing; the volume step gives
// its volume back whatever the label's value, negative ones included.
TEST(NetSurfaces, ThinRodsKeepTheirVolumeWhateverTheLabelValue) {
  const auto rod = [](int16_t value) {
    volume::LabelVolume v;
    v.geometry.dims = {36, 9, 9};
    auto labels = vtkSmartPointer<vtkShortArray>::New();
    labels->SetNumberOfTuples(36 * 9 * 9);
    int64_t n = 0;
    for (int k = 0; k < 9; ++k)
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 36; ++i) {
          const bool in = i >= 3 && i < 33 && j >= 3 && j < 6 && k >= 3 && k < 6;
          labels->SetValue(n++, in ? value : int16_t{0});
        }
    v.voxels = vtkSmartPointer<vtkImageData>::New();
    v.voxels->SetDimensions(36, 9, 9);
    v.voxels->GetPointData()->SetScalars(labels);
    return v;
  };
  std::vector<double> volumes;
  for (const int16_t value : {int16_t{5}, int16_t{-5}}) {
    const auto volume = rod(value);
    const auto cut = conforming::net_label_surface(smoothed_net(volume), value, volume.geometry);
    ASSERT_FALSE(cut.mesh.triangles.empty()) << value;
    volumes.push_back(surface::signed_volume(cut.mesh));
  }
  // 30 x 3 x 3 voxels of 1 mm.
  EXPECT_NEAR(volumes[0] / 270, 1, 0.03);
  EXPECT_DOUBLE_EQ(volumes[1], volumes[0]);
  // Without the volume step the rod is smaller by more than that.
  auto params = net_interface_params(NetOptions{});
  params.restore_volumes = false;
  conforming::InterfaceFigures figures;
  const auto volume = rod(-5);
  const auto shrunk = conforming::net_label_surface(
      conforming::label_interfaces(volume, {}, params, figures), -5, volume.geometry);
  EXPECT_LT(surface::signed_volume(shrunk.mesh), 0.97 * 270);
}

// A ball cut by the volume's top edge, as an organ by a CT's field of view:
// its cap lies flat on the edge, and no point strays past it. A cap's point
// may leave the edge inwards only to widen a thin triangle at the rim, and
// only within its box.
TEST(NetSurfaces, ALabelCutByTheVolumesEdgeEndsInAFlatCapOnIt) {
  const auto volume = testing::label_grid({26, 26, 14}, [](int i, int j, int k) -> uint8_t {
    const double x = i - 12.4, y = j - 12.7, z = k - 10.2;
    return x * x + y * y + z * z < 81 ? 1 : 0;
  });
  const double edge = 13.5;  // mm: the last voxel centre, 13, and half a voxel
  const auto net = smoothed_net(volume);
  std::vector<bool> widened(net.points.size(), false);
  for (const auto& slid : net.widened)
    if (slid.before[2] >= edge - 1e-9) widened[slid.point] = true;
  size_t on_cap = 0, left = 0;
  for (size_t p = 0; p < net.points.size(); ++p) {
    EXPECT_LE(net.points[p][2], edge + 1e-9);
    if (net.staircase[p][2] >= edge - 1e-9 && net.points[p][2] < edge - 1e-9) {
      ++left;
      EXPECT_TRUE(widened[p]) << p;
      EXPECT_GE(net.points[p][2], edge - 0.5 * 0.95 - 1e-9);
    }
    if (net.staircase[p][2] >= edge - 1e-9) ++on_cap;
  }
  EXPECT_GT(on_cap, 100u);
  EXPECT_LE(left, on_cap / 50);
  auto result = run_pipeline_on_volume(volume, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  const auto* ours = output_of(*result, 1);
  ASSERT_NE(ours, nullptr);
  EXPECT_EQ(ours->stage, "net");
  EXPECT_TRUE(result->warnings.empty());
  double top = -1e9;
  for (const auto& point : ours->mesh.points) top = std::max(top, point[2]);
  EXPECT_NEAR(top, edge, 1e-6);

  // On 3 mm slices, cut into thinner ones first, whose boxes reach across
  // several thin slices: still nothing past the edge.
  auto thick = testing::label_grid({26, 26, 6}, [](int i, int j, int k) -> uint8_t {
    const double x = i - 12.4, y = j - 12.7, z = 3.0 * k - 12;
    return x * x + y * y + z * z < 81 ? 1 : 0;
  });
  thick.geometry.spacing = {1, 1, 3};
  auto sliced = run_pipeline_on_volume(thick, MeshParams{}, {});
  ASSERT_THAT(sliced, testing::IsOk());
  const auto* cut = output_of(*sliced, 1);
  ASSERT_NE(cut, nullptr);
  double thick_top = -1e9;
  for (const auto& point : cut->mesh.points) thick_top = std::max(thick_top, point[2]);
  EXPECT_NEAR(thick_top, 16.5, 1e-6);  // the last centre, 15 mm, and half a slice
}

// The standard deviation of the distances from the axis (x, y) = centre of
// the points on the rim of `net`'s cap on the plane z = edge: points there
// with a triangle reaching below it.
double rim_radius_spread(const conforming::InterfaceSurface& net, double edge,
                         const std::array<double, 2>& centre) {
  std::vector<bool> on_rim(net.points.size(), false);
  for (const auto& t : net.triangles) {
    bool below = false;
    for (uint32_t p : t) below = below || net.staircase[p][2] < edge - 1e-9;
    if (!below) continue;
    for (uint32_t p : t)
      if (net.staircase[p][2] >= edge - 1e-9) on_rim[p] = true;
  }
  std::vector<double> radius;
  for (size_t p = 0; p < net.points.size(); ++p)
    if (on_rim[p])
      radius.push_back(std::hypot(net.points[p][0] - centre[0], net.points[p][1] - centre[1]));
  double mean = 0, squares = 0;
  for (double r : radius) mean += r / double(radius.size());
  for (double r : radius) squares += (r - mean) * (r - mean);
  return std::sqrt(squares / double(radius.size()));
}

// The rim of the cut ball's cap, smoothed along itself, runs closer to a
// circle around the ball's axis than a rim averaged with the cap's grid.
TEST(NetSurfaces, TheRimOfACapOnTheVolumesEdgeIsSmoothedAsACurve) {
  const auto volume = testing::label_grid({26, 26, 14}, [](int i, int j, int k) -> uint8_t {
    const double x = i - 12.4, y = j - 12.7, z = k - 10.2;
    return x * x + y * y + z * z < 81 ? 1 : 0;
  });
  const double edge = 13.5;
  auto params = net_interface_params(NetOptions{});
  ASSERT_TRUE(params.follow_cap_rims);
  conforming::InterfaceFigures figures;
  const auto followed = conforming::label_interfaces(volume, {}, params, figures);
  EXPECT_GT(figures.rim_points, 30u);
  params.follow_cap_rims = false;
  const auto held = conforming::label_interfaces(volume, {}, params, figures);
  EXPECT_EQ(figures.rim_points, 0u);
  const double followed_spread = rim_radius_spread(followed, edge, {12.4, 12.7});
  const double held_spread = rim_radius_spread(held, edge, {12.4, 12.7});
  EXPECT_LT(followed_spread, 0.7 * held_spread);
  EXPECT_LT(followed_spread, 0.15);
}

TEST(NetSurfaces, NestedLabelsShareTheirInterfacesWithoutOverlap) {
  auto result = run_pipeline_on_volume(
      volume::make_phantom(volume::PhantomShape::kNestedSpheres).volume, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  EXPECT_TRUE(result->warnings.empty());
  std::map<int32_t, const SurfaceResult*> out;
  for (int32_t label : {1, 2, 3}) {
    out[label] = output_of(*result, label);
    ASSERT_NE(out[label], nullptr);
    const auto& s = *out[label];
    EXPECT_EQ(s.stage, "net");
    EXPECT_TRUE(s.fidelity->within_tolerance());
    EXPECT_TRUE(s.statistics.closed);
    EXPECT_TRUE(s.statistics.manifold);
    EXPECT_EQ(s.self_intersections, uint64_t{0});
    const auto& voxels = *s.fidelity->attempts[s.fidelity->delivered].voxels;
    EXPECT_EQ(voxels.misclassified, 0u);
    EXPECT_LE(voxels.hausdorff_voxels, 1.0);
    // Marching Cubes puts a node on each voxel face; the net one in each
    // cube, two more per closed component (Euler).
    for (const auto& mc : result->surfaces)
      if (mc.label == label && mc.stage == "marching_cubes") {
        EXPECT_LE(s.statistics.nodes, mc.statistics.nodes + 2 * s.statistics.components);
      }
  }
  // Ball 1 sits in shell 2: every triangle of 1 is also one of 2's.
  EXPECT_EQ(shared_triangles(out[1]->mesh, out[2]->mesh), out[1]->mesh.triangles.size());
  // No node of the shell lies more than 0.1 voxel inside the ball.
  const auto& ball = out[1]->mesh;
  size_t inside = 0;
  for (const auto& p : out[2]->mesh.points) {
    if (winding_number(ball, p) < 0.5) continue;
    // On the shared interface the node is the ball's own: not inside.
    const bool on_ball =
        std::any_of(ball.points.begin(), ball.points.end(), [&](const auto& q) { return q == p; });
    if (!on_ball) ++inside;
  }
  EXPECT_EQ(inside, 0u);
}

// A shell a voxel and a half thick between a ball and a thicker shell, on
// 1 mm voxels: it meets the outside nowhere, so only its interfaces can give
// it back what smoothing took (held still, they left its net outside the
// volume tolerance, and it got the meshed mask). They move into its thick
// neighbours, which hardly notice: all three labels are the net within the
// voxel tolerance.
TEST(NetSurfaces, AThinLabelBetweenTwoThickOnesKeepsItsVolume) {
  const std::array<double, 3> centre{0, 0, 0};
  const auto volume = volume::rasterise(
      volume::centred_grid({45, 45, 45}, {1, 1, 1}, testing::kIdentityDirection, centre),
      [](const std::array<double, 3>& p) {
        const double r = geometry::norm(p);
        return r < 10 ? 1 : r < 11.5 ? 2 : r < 20 ? 3 : 0;
      });
  auto result = run_pipeline_on_volume(volume, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  for (const int32_t label : {1, 2, 3}) {
    const auto* s = testing::net_within_tolerance(*result, label);
    if (s == nullptr) continue;
    const auto& voxels = *s->fidelity->attempts[s->fidelity->delivered].voxels;
    EXPECT_LT(std::abs(voxels.volume_change), 0.01) << label;
    EXPECT_EQ(voxels.misclassified, 0u) << label;
  }
}

// Label 3 is four voxels in a row, touching along edges, on the diagonal
// interface between labels 1 and 2 (as the frog's tissue of four lone
// voxels sits where three others meet); label 4 is one voxel on label 1's
// face.
volume::LabelVolume labels_of_a_few_voxels() {
  return testing::label_grid({14, 14, 14}, [](int i, int j, int k) -> uint8_t {
    if (k == 5 && i + j == 14 && i >= 5 && i <= 8) return 3;
    if (i == 1 && j == 5 && k == 5) return 4;
    if (std::min({i, j, k}) < 2 || std::max({i, j, k}) > 11) return 0;
    return i + j + k < 20 ? 1 : 2;
  });
}

// Both stencils (a point per sheet, and one per cube as on thinner slices)
// keep every point next to a label of a few voxels where it is: the lone
// voxel's surface is its cube.
TEST(NetSurfaces, PointsNextToALabelOfAFewVoxelsStayWithEitherStencil) {
  const auto volume = labels_of_a_few_voxels();
  for (const bool split : {true, false}) {
    auto params = net_interface_params(NetOptions{});
    params.split_sheets = split;
    conforming::InterfaceFigures figures;
    const auto net = conforming::label_interfaces(volume, {}, params, figures);
    const auto lone = conforming::net_label_surface(net, 4, volume.geometry);
    ASSERT_EQ(lone.mesh.points.size(), 8u) << split;
    EXPECT_EQ(lone.mesh.points, lone.staircase.points) << split;
    EXPECT_NEAR(surface::signed_volume(lone.mesh), 1.0, 1e-12) << split;
    EXPECT_GE(figures.fixed_points, 8u) << split;
  }
}

// A label of a few voxels keeps its voxels' shape through the pipeline.
// Smoothed, the row kept 39 % of its volume (outside the 10 % allowed
// labels of fewer than 1,000 voxels), and its split copies, moved a tenth
// of the way, took 11 % of the frog's row.
TEST(NetSurfaces, ALabelOfAFewVoxelsKeepsItsVoxelsShape) {
  const auto volume = labels_of_a_few_voxels();
  auto result = run_pipeline_on_volume(volume, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  for (const int32_t label : {1, 2, 3, 4}) {
    const auto* s = testing::net_within_tolerance(*result, label);
    if (s == nullptr) continue;
    EXPECT_TRUE(s->statistics.closed) << label;
    EXPECT_TRUE(s->statistics.manifold) << label;
    EXPECT_EQ(s->self_intersections.value_or(1), 0u) << label;
  }
  // The lone voxel is its cube; the row loses only what its copies split
  // along the shared edges move in (kSplitNudge).
  const auto* lone = testing::output_of(*result, 4);
  ASSERT_NE(lone, nullptr);
  EXPECT_NEAR(lone->statistics.volume_mm3, 1.0, 1e-9);
  const auto* row = testing::output_of(*result, 3);
  ASSERT_NE(row, nullptr);
  EXPECT_GT(row->statistics.volume_mm3, 0.9 * 4);
  EXPECT_LE(row->statistics.volume_mm3, 4.0);
}

// Analytic shapes on the grids hospitals send: closer to the true surface,
// with truer normals, than the Slicer-like pipeline on the same volume. The
// thin tube is three voxels across: its cross-section keeps round only
// where the smoothing pauses to give the volume back (docs/pipeline.md,
// the net's step 3).
TEST(NetSurfaces, ThickSliceShapesAreTruerThanTheSlicerLikePipeline) {
  struct Case {
    testing::AnalyticShape shape;
    std::array<double, 3> spacing;
  };
  const std::vector<Case> cases{{testing::sphere_shape(25), {0.6, 0.6, 4}},
                                {testing::ellipsoid_shape(32, 22, 15), {0.6, 0.6, 4}},
                                {testing::sphere_shape(25), {1, 1, 3}},
                                {testing::ellipsoid_shape(32, 22, 15), {1, 1, 3}},
                                {testing::torus_shape(25, 9), {3, 3, 3}},
                                {testing::torus_shape(25, 4.5, "thin tube"), {3, 3, 3}}};
  for (const auto& [shape, spacing] : cases) {
    const auto both = both_surfaces(testing::sample_shape(shape, spacing));
    ASSERT_EQ(both.slicer.size(), 1u);
    ASSERT_THAT(both.result, testing::IsOk());
    const auto* ours = both.ours();
    ASSERT_NE(ours, nullptr);
    const auto& slicer = both.slicer;
    EXPECT_EQ(ours->stage, "net") << shape.name;
    const auto mine = testing::shape_error(ours->mesh, shape);
    const auto theirs = testing::shape_error(slicer.front().mesh, shape);
    EXPECT_LT(mine.rms_mm, theirs.rms_mm) << shape.name;
    EXPECT_LT(mine.normal_p95_deg, theirs.normal_p95_deg) << shape.name;
    // Within a fifth of the largest spacing of the true surface.
    EXPECT_LT(mine.rms_mm, 0.2 * spacing[2]) << shape.name;
    // On thick slices the walls slope evenly between slices (on 4 mm slices
    // their normals' 95th percentile was 14-17 degrees while the thin slices
    // kept a stair), and the thinner grid's net is smoothed long enough to
    // round the ellipsoid on 1 x 1 x 3 mm slices (11.4 degrees at the
    // isotropic grids' rounds).
    if (spacing[2] > spacing[0]) {
      EXPECT_LT(mine.normal_p95_deg, 10) << shape.name << " " << spacing[2];
    }
  }
}

// The torus's top and the ellipsoid's poles lie on slice centres of these
// grids centred on the shapes, so their voxels end a slice short of the
// true shape there (the 3 mm torus's normals' 95th percentile 11.2
// degrees). Half a slice up they end between slices, as organs do, and
// the net is within a quarter of the smallest spacing and 10 degrees,
// closer with truer normals than the Slicer-like surface.
TEST(NetSurfaces, ShapesEndingBetweenSlicesAreTruerThanTheSlicerLikePipeline) {
  struct Case {
    testing::AnalyticShape shape;
    std::array<double, 3> spacing;
  };
  const std::vector<Case> cases{{testing::torus_shape(25, 9), {3, 3, 3}},
                                {testing::ellipsoid_shape(32, 22, 15), {3, 3, 3}},
                                {testing::torus_shape(25, 9), {1, 1, 3}},
                                {testing::ellipsoid_shape(32, 22, 15), {1, 1, 3}}};
  for (const auto& [shape, spacing] : cases) {
    SCOPED_TRACE(shape.name + " " + std::to_string(spacing[0]));
    const auto both = both_surfaces(testing::sample_shape(shape, spacing, 0, 0.5));
    ASSERT_EQ(both.slicer.size(), 1u);
    ASSERT_THAT(both.result, testing::IsOk());
    const auto* ours = both.ours();
    ASSERT_NE(ours, nullptr);
    EXPECT_EQ(ours->stage, "net");
    const auto mine = testing::shape_error(ours->mesh, shape);
    const auto theirs = testing::shape_error(both.slicer.front().mesh, shape);
    EXPECT_LT(mine.rms_mm, theirs.rms_mm);
    EXPECT_LT(mine.normal_p95_deg, theirs.normal_p95_deg);
    EXPECT_LT(mine.rms_mm, 0.25 * spacing[0]);
    EXPECT_LT(mine.normal_p95_deg, 10);
  }
}

// Where a shape ends between two slice centres decides how much of it the
// voxels show: on 1 x 1 x 3 mm slices the torus whose top lies on a slice
// centre is farther from the true one than the Slicer-like surface, and the
// thin tube half a slice up has wider normals (docs/benchmarks.md, "Where
// the slices fall"). Over shifts of 0, 1/4, 1/2 and 3/4 of a slice the net's
// mean error is the smaller in both.
TEST(NetSurfaces, AveragedOverWhereSlicesFallShapesAreTruerThanTheSlicerLike) {
  constexpr int kShifts = 4;
  for (const auto& shape :
       {testing::torus_shape(25, 9), testing::torus_shape(25, 4.5, "thin tube")}) {
    SCOPED_TRACE(shape.name);
    double mine_rms = 0, mine_p95 = 0, theirs_rms = 0, theirs_p95 = 0;
    for (int shift = 0; shift < kShifts; ++shift) {
      const auto both =
          both_surfaces(testing::sample_shape(shape, {1, 1, 3}, 0, double(shift) / kShifts));
      ASSERT_EQ(both.slicer.size(), 1u);
      ASSERT_THAT(both.result, testing::IsOk());
      const auto* ours = both.ours();
      ASSERT_NE(ours, nullptr);
      EXPECT_EQ(ours->stage, "net") << shift;
      const auto mine = testing::shape_error(ours->mesh, shape);
      const auto theirs = testing::shape_error(both.slicer.front().mesh, shape);
      mine_rms += mine.rms_mm / kShifts;
      mine_p95 += mine.normal_p95_deg / kShifts;
      theirs_rms += theirs.rms_mm / kShifts;
      theirs_p95 += theirs.normal_p95_deg / kShifts;
    }
    EXPECT_LT(mine_rms, theirs_rms);
    EXPECT_LT(mine_p95, theirs_p95);
  }
}

// A tube 9 mm across whose top and bottom lie on drawn slices' centres: two
// slices hold it, and its voxels end a whole slice short of the next. The
// thinner grid keeps its voxels' volume, so the net does too and is
// delivered (a thinner grid 7 % short gave a net outside the tolerance, and
// the meshed mask was delivered: normals' p95 44 and 37 degrees).
TEST(NetSurfaces, ATubeEndingOnDrawnSlicesIsDeliveredSmooth) {
  const auto tube = testing::torus_shape(25, 4.5, "thin tube");
  for (const std::array<double, 3> spacing :
       {std::array<double, 3>{1, 1, 3}, std::array<double, 3>{0.6, 0.6, 4}}) {
    const auto both = both_surfaces(testing::sample_shape(tube, spacing, 0, 0.5));
    ASSERT_THAT(both.result, testing::IsOk());
    const auto* ours = both.ours();
    ASSERT_NE(ours, nullptr);
    EXPECT_EQ(ours->stage, "net") << spacing[2];
    EXPECT_TRUE(both.result->warnings.empty()) << spacing[2];
    const auto mine = testing::shape_error(ours->mesh, tube);
    EXPECT_LT(mine.normal_p95_deg, 30) << spacing[2];
    EXPECT_LT(mine.rms_mm, 0.25 * spacing[2]) << spacing[2];
  }
}

// The share of a column's wall area (triangles facing within 25 degrees of
// the horizontal) that faces within 10 degrees of a voxel axis although the
// true wall there faces more than 10 degrees away from every axis: in-plane
// pixel steps left standing.
double stepped_wall_share(const surface::TriangleMesh& mesh, const testing::AnalyticShape& column) {
  const double near_axis = std::cos(surface::kAxisAlignedDeg * M_PI / 180);
  double stepped = 0, away = 0;
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const auto n = geometry::cross(geometry::sub(b, a), geometry::sub(c, a));
    const double area = 0.5 * geometry::norm(n);
    if (area == 0) continue;
    const auto unit = geometry::scale(n, 0.5 / area);
    if (std::abs(unit[2]) > std::sin(25 * M_PI / 180)) continue;
    const auto truth =
        column.normal(geometry::scale(geometry::add(a, geometry::add(b, c)), 1.0 / 3));
    if (std::max(std::abs(truth[0]), std::abs(truth[1])) > near_axis) continue;
    away += area;
    if (std::max({std::abs(unit[0]), std::abs(unit[1]), std::abs(unit[2])}) > near_axis)
      stepped += area;
  }
  return away > 0 ? stepped / away : 0;
}

// A column's walls, cut by the volume's edges as organs are by a CT slab:
// the net's walls face their true directions, with the pixels' steps gone
// where the wall turns away from the axes (on 4 mm slices, smoothed at the
// isotropic grids' rounds, 12 % of that area still faced an axis, which
// made up for walls near the axes that face a little off them, so the
// whole share looked true). The Slicer-like surface leans its walls off the
// axes on 4 mm slices, below the true shape's share.
TEST(NetSurfaces, ColumnWallsFaceTheirTrueDirections) {
  const auto column = testing::column_shape(20);
  for (const std::array<double, 3>& spacing :
       {std::array<double, 3>{0.6, 0.6, 4}, std::array<double, 3>{0.976562, 0.976562, 2}}) {
    const auto v = testing::sample_shape(column, spacing);
    const auto both = both_surfaces(v);
    ASSERT_EQ(both.slicer.size(), 1u);
    ASSERT_THAT(both.result, testing::IsOk());
    const auto* ours = both.ours();
    ASSERT_NE(ours, nullptr);
    EXPECT_EQ(ours->stage, "net") << spacing[2];
    const double truth = surface::axis_aligned_share(ours->mesh, v.geometry, column.normal);
    EXPECT_GT(truth, 0.18) << spacing[2];
    EXPECT_LT(truth, 0.25) << spacing[2];
    EXPECT_LT(stepped_wall_share(ours->mesh, column), 0.03) << spacing[2];
    const auto mine = testing::shape_error(ours->mesh, column);
    const auto theirs = testing::shape_error(both.slicer.front().mesh, column);
    EXPECT_LT(mine.normal_p95_deg, theirs.normal_p95_deg) << spacing[2];
    if (spacing[2] == 4) {
      EXPECT_LT(surface::axis_aligned_share(both.slicer.front().mesh, v.geometry), truth - 0.05);
    }
  }
}

// Rings 9 and 18 mm thick on slices 3 and 4 mm apart: the thick slices'
// cubic interpolation keeps them whole between slices, and the net is
// delivered within the voxel tolerance, closer to the true ring than the
// Slicer-like surface.
TEST(NetSurfaces, ThinRingsOnThickSlicesKeepTheNet) {
  struct Case {
    testing::AnalyticShape shape;
    std::array<double, 3> spacing;
    std::string stage;
  };
  // Points held between the drawn slices around their cubes keep the drawn
  // voxel centres on their side: the full smoothing is delivered (carried
  // onto a drawn slice from beside it, points put 1-3 % of these rings'
  // boundary voxel centres on the wrong side, and the net smoothed half as
  // much, or the mask, was delivered).
  const std::vector<Case> cases{{testing::torus_shape(25, 4.5, "thin tube"), {0.6, 0.6, 4}, "net"},
                                {testing::torus_shape(25, 9), {0.6, 0.6, 4}, "net"},
                                {testing::torus_shape(25, 4.5, "thin tube"), {1, 1, 3}, "net"}};
  for (const auto& [shape, spacing, stage] : cases) {
    const std::string name = shape.name + " on " + std::to_string(spacing[2]) + " mm";
    const auto both = both_surfaces(testing::sample_shape(shape, spacing));
    ASSERT_EQ(both.slicer.size(), 1u);
    ASSERT_THAT(both.result, testing::IsOk());
    const auto* ours = both.ours();
    ASSERT_NE(ours, nullptr);
    EXPECT_EQ(ours->stage, stage) << name;
    EXPECT_TRUE(ours->fidelity->within_tolerance()) << name;
    EXPECT_TRUE(ours->statistics.closed) << name;
    EXPECT_TRUE(ours->statistics.manifold) << name;
    EXPECT_EQ(ours->self_intersections, uint64_t{0}) << name;
    const auto mine = testing::shape_error(ours->mesh, shape);
    const auto theirs = testing::shape_error(both.slicer.front().mesh, shape);
    EXPECT_LT(mine.rms_mm, theirs.rms_mm) << name;
  }
}

// On 1 x 1 x 3 mm slices the thinner slices between drawn ones are
// interpolated and step a whole pixel at a time; held to those pixels, the
// surface keeps the steps as ridges around a sphere. Boxes that widen
// between drawn slices let the ridges go: the normals' 95th percentile
// falls by more than a seventh, the distance to the true sphere does not
// grow, and the net stays within the voxel tolerance.
TEST(NetSurfaces, WiderBoxesBetweenDrawnSlicesSmoothTheInterpolatedSteps) {
  const auto sphere = testing::sphere_shape(25);
  MeshParams narrow;
  narrow.net.between_drawn_widening = 0;
  for (const double degrees : {0.0, 25.0}) {
    const auto v = testing::sample_shape(sphere, {1, 1, 3}, degrees);
    const auto wide = run_pipeline_on_volume(v, MeshParams{}, {});
    const auto held = run_pipeline_on_volume(v, narrow, {});
    ASSERT_THAT(wide, testing::IsOk());
    ASSERT_THAT(held, testing::IsOk());
    const auto* smoothed = output_of(*wide, 1);
    const auto* stepped = output_of(*held, 1);
    ASSERT_NE(smoothed, nullptr);
    ASSERT_NE(stepped, nullptr);
    EXPECT_EQ(smoothed->stage, "net") << degrees;
    EXPECT_TRUE(smoothed->fidelity->within_tolerance()) << degrees;
    const auto smooth_error = testing::shape_error(smoothed->mesh, sphere);
    const auto stepped_error = testing::shape_error(stepped->mesh, sphere);
    EXPECT_LT(smooth_error.normal_p95_deg, 0.85 * stepped_error.normal_p95_deg) << degrees;
    EXPECT_LT(smooth_error.rms_mm, stepped_error.rms_mm + 0.01) << degrees;
  }
}

// A sphere on 1 x 1 x 3 mm slices, straight and turned: 95 % of its area
// within 10 degrees of the true normal, poles included, where the last
// drawn slice's disc must round off into a cap.
TEST(NetSurfaces, ASphereOnThickSlicesHasTrueNormalsToItsPoles) {
  const auto sphere = testing::sphere_shape(25);
  for (const double degrees : {0.0, 25.0}) {
    const auto result =
        run_pipeline_on_volume(testing::sample_shape(sphere, {1, 1, 3}, degrees), {}, {});
    ASSERT_THAT(result, testing::IsOk());
    const auto* ours = output_of(*result, 1);
    ASSERT_NE(ours, nullptr);
    EXPECT_EQ(ours->stage, "net") << degrees;
    EXPECT_LT(testing::shape_error(ours->mesh, sphere).normal_p95_deg, 10) << degrees;
  }
}

// Five organs on three 5 mm slices, touching along junction curves. Boxes
// that widen between drawn slices would let a junction curve's points
// crowd together into needles and crossings, so junction points keep narrow
// boxes, and a junction point where its curve turns back stays fixed: every
// net surface stays closed, manifold, without crossings and without
// triangles below 15 degrees.
TEST(NetSurfaces, OrgansOnThreeThickSlicesKeepTheirAngles) {
  const auto result =
      run_pipeline_on_volume(testing::five_organs_on_three_slices(), MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  size_t nets = 0, within = 0;
  for (const auto& s : result->surfaces) {
    if (!s.is_output || s.stage != "net") continue;
    ++nets;
    if (s.fidelity->within_tolerance()) ++within;
    EXPECT_TRUE(s.statistics.closed) << s.label;
    EXPECT_TRUE(s.statistics.manifold) << s.label;
    EXPECT_EQ(s.self_intersections, uint64_t{0}) << s.label;
    EXPECT_GE(s.statistics.min_angle_deg, 15) << s.label;
  }
  // A thin voxel takes only a label its pixel is drawn with, so where two
  // organs meet the large one between slices neither strays a voxel from
  // its own: every organ is the net, within the tolerance.
  EXPECT_EQ(nets, 5u);
  EXPECT_EQ(within, 5u);
}

// The guard's ladder when the full smoothing fails: with Taubin steps that
// inflate more than they shrink, the net bulges past the voxels of a ring on
// 1 x 1 x 3 mm slices, and the guard tries the net smoothed half as much
// before the meshed mask; that one is within the tolerance and closed, and
// the delivered attempt exceeds the tolerance least.
TEST(NetSurfaces, ANetSmoothedPastTheVoxelsFallsBackToTheLighterNet) {
  const auto ring = testing::torus_shape(25, 9);
  MeshParams params;
  params.net.inflate_step = -0.6;
  // At the isotropic grids' rounds: four times as many take the lighter net
  // past the voxels too.
  params.net.thin_grid_rounds_factor = 1;
  auto result = run_pipeline_on_volume(testing::sample_shape(ring, {1, 1, 3}), params, {});
  ASSERT_THAT(result, testing::IsOk());
  const auto* ours = output_of(*result, 1);
  ASSERT_NE(ours, nullptr);
  const auto& fidelity = *ours->fidelity;
  ASSERT_GE(fidelity.attempts.size(), 2u);
  EXPECT_EQ(fidelity.attempts[0].method, SurfaceAttemptMethod::kNet);
  EXPECT_FALSE(fidelity.attempts[0].within_tolerance);
  EXPECT_EQ(fidelity.attempts[1].method, SurfaceAttemptMethod::kNetLighter);
  const double delivered = excess_over(fidelity.attempts[fidelity.delivered], fidelity.tolerance);
  for (const auto& attempt : fidelity.attempts)
    EXPECT_LE(delivered, excess_over(attempt, fidelity.tolerance)) << method_name(attempt.method);
  EXPECT_EQ(ours->stage, "net_lighter");
  EXPECT_TRUE(fidelity.within_tolerance());
  EXPECT_TRUE(ours->statistics.closed);
  EXPECT_TRUE(ours->statistics.manifold);
  EXPECT_EQ(ours->self_intersections, uint64_t{0});
}

TEST(NetSurfaces, CoarseIsotropicSphereIsWithinAQuarterVoxel) {
  const auto shape = testing::sphere_shape(25);
  auto result = run_pipeline_on_volume(testing::sample_shape(shape, {3, 3, 3}), MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  const auto* ours = output_of(*result, 1);
  ASSERT_NE(ours, nullptr);
  const auto error = testing::shape_error(ours->mesh, shape);
  EXPECT_LT(error.rms_mm, 0.25 * 3);
  EXPECT_LT(error.normal_p95_deg, 10);
}

// The 3 mm MR of 23 labels: every label delivered within the voxel
// tolerance (the thin ones between organs take their volume back from
// them); the net's surfaces closed, manifold, without thin triangles (at
// most one in a thousand below 30 degrees), faithful to every voxel centre
// and far smoother than Marching Cubes; so --strict accepts the run.
TEST(NetSurfacesRealData, MrLabelsAreFaithfulAndSmooth) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("totalseg_example_seg_mr.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  std::vector<double> ours, marching_cubes;
  size_t outputs = 0, outside = 0, nets = 0;
  uint64_t triangles = 0, below_30 = 0;
  for (const auto& s : result->surfaces) {
    if (s.stage == "marching_cubes") marching_cubes.push_back(s.axis_aligned_share.value_or(0));
    if (!s.is_output) continue;
    ++outputs;
    if (!s.fidelity->within_tolerance()) ++outside;
    ours.push_back(s.axis_aligned_share.value_or(1));
    if (s.stage != "net") continue;
    ++nets;
    EXPECT_TRUE(s.statistics.closed) << s.label;
    EXPECT_TRUE(s.statistics.manifold) << s.label;
    EXPECT_EQ(s.self_intersections, uint64_t{0}) << s.label;
    // Thin triangles widened: below 3 degrees without it, and 0.8 % of
    // them below 30 degrees when only those below 20 were widened.
    EXPECT_GE(s.statistics.min_angle_deg, 25) << s.label;
    triangles += s.statistics.triangles;
    below_30 += s.statistics.triangles_below_30_deg;
    const auto& voxels = *s.fidelity->attempts[s.fidelity->delivered].voxels;
    EXPECT_EQ(voxels.misclassified, 0u) << s.label;
    EXPECT_LE(voxels.hausdorff_voxels, 1.0) << s.label;
  }
  EXPECT_EQ(outputs, 23u);
  EXPECT_GE(nets, 21u);
  EXPECT_EQ(outside, 0u);
  EXPECT_LE(below_30 * 1000, triangles);
  EXPECT_TRUE(result->warnings.empty());
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(ours), median(marching_cubes) / 3);

  MeshParams strict;
  strict.guard.strict = true;
  EXPECT_THAT(run_pipeline(path, strict, {}), testing::IsOk());
}

// The volumes with the most and the smallest labels: 1 mm brain (40
// labels, two of four voxels) and frog (25 tissues, one of four lone
// voxels where three others meet). Every label is the net within the
// voxel tolerance, closed, manifold, without self-intersection, and with
// at most one triangle in a thousand below 30 degrees: the run has no
// warning, so --strict would accept it.
class EveryLabelTheNet : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryLabelTheNet, WithinTheVoxelToleranceWithoutWarnings) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  size_t nets = 0;
  uint64_t triangles = 0, below_30 = 0;
  for (const auto& s : result->surfaces) {
    if (!s.is_output) continue;
    SCOPED_TRACE("label " + std::to_string(s.label));
    EXPECT_EQ(s.stage, "net");
    ASSERT_TRUE(s.fidelity.has_value());
    EXPECT_TRUE(s.fidelity->within_tolerance());
    EXPECT_TRUE(s.statistics.closed);
    EXPECT_TRUE(s.statistics.manifold);
    EXPECT_EQ(s.self_intersections, uint64_t{0});
    nets += s.stage == "net";
    triangles += s.statistics.triangles;
    below_30 += s.statistics.triangles_below_30_deg;
  }
  EXPECT_EQ(nets, result->input.statistics.labels.size());
  EXPECT_LE(below_30 * 1000, triangles);
  for (const auto& warning : result->warnings)
    ADD_FAILURE() << "label " << warning.label << ": " << warning.reason;
}

INSTANTIATE_TEST_SUITE_P(SharedVolumes, EveryLabelTheNet,
                         ::testing::Values("iso2mesh_brain_seg_converted.nii.gz",
                                           "frogtissue.mhd"));

// Touching MR organs share their interfaces: no node of one label's surface
// lies inside another's by more than a tenth of a voxel, where the same
// labels smoothed each on its own (the Slicer-like surfaces) enter each
// other with one node in a hundred or more.
TEST(NetSurfacesRealData, MrLabelsDoNotEnterEachOther) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("totalseg_example_seg_mr.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  auto volume = volume::read_label_volume(path, {}, RunContext{});
  ASSERT_THAT(volume, testing::IsOk());
  const auto statistics = volume::compute_label_statistics(*volume);
  std::vector<int32_t> labels;
  std::vector<const surface::TriangleMesh*> ours;
  for (const auto& l : statistics.labels) {
    if (l.label == 0) continue;
    const auto* s = output_of(*result, l.label);
    ASSERT_NE(s, nullptr) << l.label;
    labels.push_back(l.label);
    ours.push_back(&s->mesh);
  }
  ASSERT_GE(labels.size(), 20u);
  const auto slicer = testing::slicer_like_surfaces(*volume, statistics, labels);
  ASSERT_EQ(slicer.size(), labels.size());
  std::vector<const surface::TriangleMesh*> separate;
  for (const auto& s : slicer) separate.push_back(&s.mesh);
  const auto& spacing = volume->geometry.spacing;
  const double depth = 0.1 * *std::min_element(spacing.begin(), spacing.end());
  const auto shared = testing::nodes_inside_others(ours, labels, *volume, depth);
  const auto apart = testing::nodes_inside_others(separate, labels, *volume, depth);
  EXPECT_GT(shared.nodes, 20000u);
  EXPECT_EQ(shared.inside, 0u);
  EXPECT_GT(apart.inside, apart.nodes / 100);
  EXPECT_GE(apart.labels_entering, 5u);
}

// The whole-brain segmentation's 40 labels touch one another in every way
// voxels can (along edges, at corners, around tunnels): each label's cut is
// still a closed 2-manifold.
// Moves that widen thin triangles and make triangles cross are taken back,
// by halves first: the pairs left are those a full search finds, none holds
// a moved point, and the thinnest triangle is wider than when every such
// move went wholly back (the brain's net has such moves).
TEST(NetSurfacesRealData, CrossingMovesAreTakenBack) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("iso2mesh_brain_seg_converted.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  const auto volume = volume::read_label_volume(path, {}, {});
  ASSERT_THAT(volume, testing::IsOk());
  conforming::InterfaceFigures figures;
  auto net = conforming::label_interfaces(*volume, testing::label_values(*volume),
                                          net_interface_params(NetOptions{}), figures);
  const size_t moved = net.widened.size();
  EXPECT_EQ(moved, figures.widened_points);
  ASSERT_GT(moved, 100u);
  const auto pairs = conforming::crossings_after_taking_back_slides(net);
  // Moves taken back wholly leave the list; those taken back in part stay.
  size_t taken_back = moved - net.widened.size();
  for (const auto& slid : net.widened)
    if (slid.halvings > 0) ++taken_back;
  EXPECT_GT(taken_back, 0u);
  // Half a move often clears the crossing and keeps part of the wider
  // angle: no triangle is left below 5 degrees.
  const double smallest =
      surface::compute_surface_statistics({net.points, net.triangles}).min_angle_deg;
  EXPECT_GT(smallest, 5);
  EXPECT_EQ(pairs, surface::crossing_triangles(net.points, net.triangles));
  std::vector<bool> still_moved(net.points.size(), false);
  for (const auto& slid : net.widened) still_moved[slid.point] = true;
  for (const auto& [s, t] : pairs)
    for (const uint32_t triangle : {s, t})
      for (const uint32_t p : net.triangles[triangle]) EXPECT_FALSE(still_moved[p]) << p;
}

// The prostate MR, 0.6 x 0.6 x 4 mm slices, two touching labels: cut into
// thinner slices, each thin voxel taking a label its pixel is drawn with,
// both labels are delivered as the net within the voxel tolerance, and no
// junction curve folds a quad onto a line (fixed where it turns back).
TEST(NetSurfacesRealData, ProstateOnThickSlicesIsFaithfulWithoutNeedles) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("msd_prostate_mask_00.nii");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  const auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  size_t outputs = 0;
  uint64_t triangles = 0, below_30 = 0;
  for (const auto& s : result->surfaces) {
    if (!s.is_output) continue;
    ++outputs;
    EXPECT_EQ(s.stage, "net") << s.label;
    EXPECT_TRUE(s.fidelity->within_tolerance()) << s.label;
    EXPECT_TRUE(s.statistics.closed) << s.label;
    EXPECT_TRUE(s.statistics.manifold) << s.label;
    EXPECT_EQ(s.self_intersections, uint64_t{0}) << s.label;
    EXPECT_GE(s.statistics.min_angle_deg, 25) << s.label;
    triangles += s.statistics.triangles;
    below_30 += s.statistics.triangles_below_30_deg;
  }
  EXPECT_EQ(outputs, 2u);
  EXPECT_LE(below_30 * 1000, triangles);
}

TEST(NetSurfacesRealData, EveryBrainLabelIsAClosedManifold) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("iso2mesh_brain_seg_converted.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto v = volume::read_label_volume(path, {}, RunContext{});
  ASSERT_THAT(v, testing::IsOk());
  const auto net = smoothed_net(*v);
  const auto net_crossings = surface::crossing_triangles(net.points, net.triangles);
  uint32_t split = 0;
  uint64_t crossings = 0;
  for (const auto& label : volume::compute_label_statistics(*v).labels) {
    const auto cut = conforming::net_label_surface(net, label.label, v->geometry);
    const auto s = surface::compute_surface_statistics(cut.mesh);
    EXPECT_TRUE(s.closed) << label.label;
    EXPECT_EQ(s.non_manifold_edges, 0u) << label.label;
    EXPECT_EQ(s.non_manifold_vertices, 0u) << label.label;
    split += cut.split_points;
    // The count from the net's pairs is CGAL's count on the label alone.
    const uint64_t from_net =
        conforming::net_label_self_intersections(net, net_crossings, cut, label.label);
    EXPECT_EQ(from_net, surface::count_self_intersections(cut.mesh).value_or(UINT64_MAX))
        << label.label;
    crossings += from_net;
  }
  EXPECT_GT(split, 1000u);   // the splitting is exercised
  EXPECT_GT(crossings, 0u);  // and so is the count
}

}  // namespace
}  // namespace labelmesh
