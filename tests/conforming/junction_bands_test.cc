// SPDX-License-Identifier: AGPL-3.0-or-later
// Where three labels meet the net smooths the surface as anywhere else;
// only around a small label does it hold the junction curves sharp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <vector>

#include "core/conforming/label_interfaces.h"
#include "core/conforming/net_label_surface.h"
#include "core/conforming/widen_small_angles.h"
#include "core/pipeline/label_net_surfaces.h"
#include "core/pipeline/pipeline.h"
#include "core/surface/crossing_triangles.h"
#include "core/surface/surface_statistics.h"
#include "core/util/vec3.h"
#include "core/volume/phantom_grid.h"
#include "core/volume/read_label_volume.h"
#include "support/label_volumes.h"
#include "support/mesh_results.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

using geometry::Vec3;

using testing::output_of;

// A ball of radius 12 voxels on 3 mm voxels cut by an oblique gap one voxel
// wide into labels 1 and 2, with a cube of label 3, `edge` voxels along each
// axis, across the gap at the ball's centre.
volume::LabelVolume ball_with_a_cube_across_its_gap(int64_t edge) {
  constexpr double kVoxel = 3;
  const Vec3 across = geometry::scale(Vec3{1, 1, 0.6}, 1 / std::sqrt(2.36));
  auto volume = volume::rasterise(volume::centred_grid({31, 31, 31}, {kVoxel, kVoxel, kVoxel},
                                                       testing::kIdentityDirection, {0, 0, 0}),
                                  [&](const Vec3& p) {
                                    if (geometry::norm(p) > 12 * kVoxel) return 0;
                                    const double along = geometry::dot(p, across);
                                    return along < -0.5 * kVoxel ? 1 : along > 0.5 * kVoxel ? 2 : 0;
                                  });
  const auto& d = volume.geometry.dims;
  auto* labels = static_cast<uint8_t*>(volume.voxels->GetScalarPointer());
  const int64_t first = d[0] / 2 - edge / 2;
  for (int64_t k = first; k < first + edge; ++k)
    for (int64_t j = first; j < first + edge; ++j)
      for (int64_t i = first; i < first + edge; ++i) labels[(k * d[1] + j) * d[0] + i] = 3;
  return volume;
}

// The normal of the oblique gap in ball_with_a_cube_across_its_gap.
const Vec3 kAcrossTheGap = geometry::scale(Vec3{1, 1, 0.6}, 1 / std::sqrt(2.36));

// The area-weighted share of `mesh`'s triangles along the gap (centroid
// within 3 mm of its middle plane and 24 mm of the ball's centre) whose
// normal lies within 15 degrees of the gap's.
double share_along_the_gap(const surface::TriangleMesh& mesh) {
  double near = 0, along = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.points[t[0]];
    const Vec3& b = mesh.points[t[1]];
    const Vec3& c = mesh.points[t[2]];
    const Vec3 centroid = geometry::scale(geometry::add(geometry::add(a, b), c), 1.0 / 3);
    if (std::abs(geometry::dot(centroid, kAcrossTheGap)) > 3 || geometry::norm(centroid) > 24)
      continue;
    const Vec3 n = geometry::cross(geometry::sub(b, a), geometry::sub(c, a));
    const double area = 0.5 * geometry::norm(n);
    if (area == 0) continue;
    near += area;
    if (std::abs(geometry::dot(n, kAcrossTheGap)) >= 2 * area * std::cos(15 * M_PI / 180))
      along += area;
  }
  return near > 0 ? along / near : 0;
}

// Two halves of a ball a voxel apart across an oblique gap: one point per
// cube would hold both faces of the gap in the cubes it crosses, and they
// kept the voxels' steps; with a point per sheet each face follows the gap.
TEST(JunctionBands, FacesAVoxelApartPartAndFollowTheirGap) {
  const auto volume = ball_with_a_cube_across_its_gap(0);
  auto params = net_interface_params(NetOptions{});
  ASSERT_TRUE(params.split_sheets);
  conforming::InterfaceFigures figures;
  const auto split = conforming::label_interfaces(volume, {}, params, figures);
  params.split_sheets = false;
  const auto shared = conforming::label_interfaces(volume, {}, params, figures);
  // Parted, the two faces do not pass through each other.
  EXPECT_TRUE(surface::crossing_triangles(split.points, split.triangles).empty());
  for (const int32_t label : {1, 2}) {
    const double parted =
        share_along_the_gap(conforming::net_label_surface(split, label, volume.geometry).mesh);
    const double held =
        share_along_the_gap(conforming::net_label_surface(shared, label, volume.geometry).mesh);
    EXPECT_GT(parted, 0.8) << label;
    EXPECT_GT(parted, held + 0.3) << label;
  }
  auto result = run_pipeline_on_volume(volume, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  for (const int32_t label : {1, 2}) {
    const auto* s = testing::net_within_tolerance(*result, label);
    if (s == nullptr) continue;
    EXPECT_TRUE(s->statistics.closed) << label;
    EXPECT_TRUE(s->statistics.manifold) << label;
    EXPECT_EQ(s->self_intersections, uint64_t{0}) << label;
  }
}

// The share of `mesh`'s edges between two triangles whose normals differ by
// more than `degrees`.
double share_of_sharp_edges(const surface::TriangleMesh& mesh, double degrees) {
  std::map<std::array<uint32_t, 2>, std::vector<Vec3>> normals;
  for (const auto& t : mesh.triangles) {
    Vec3 n = geometry::cross(geometry::sub(mesh.points[t[1]], mesh.points[t[0]]),
                             geometry::sub(mesh.points[t[2]], mesh.points[t[0]]));
    const double length = geometry::norm(n);
    if (length == 0) continue;
    n = geometry::scale(n, 1 / length);
    for (int k = 0; k < 3; ++k)
      normals[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}].push_back(n);
  }
  size_t edges = 0, sharp = 0;
  for (const auto& [edge, around] : normals) {
    if (around.size() != 2) continue;
    ++edges;
    if (geometry::dot(around[0], around[1]) < std::cos(degrees * M_PI / 180)) ++sharp;
  }
  return edges > 0 ? double(sharp) / double(edges) : 0;
}

// A label of 27 voxels keeps the junction curves around it, and its volume;
// around one of 512 voxels no point is held to a curve.
TEST(JunctionBands, SmallLabelsKeepTheirJunctionCurves) {
  const auto small = ball_with_a_cube_across_its_gap(3);
  conforming::InterfaceFigures figures;
  conforming::label_interfaces(small, {}, net_interface_params(NetOptions{}), figures);
  EXPECT_GT(figures.curve_points, 0u);
  auto result = run_pipeline_on_volume(small, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  for (const int32_t label : {1, 2, 3}) testing::net_within_tolerance(*result, label);

  conforming::label_interfaces(ball_with_a_cube_across_its_gap(8), {},
                               net_interface_params(NetOptions{}), figures);
  EXPECT_GT(figures.junction_points, 50u);
  EXPECT_EQ(figures.curve_points, 0u);
}

// TotalSegmentator's 3 mm whole-body segmentation: organs touch one another
// nearly everywhere, across gaps a voxel wide and along thin tissues. Held to
// the junction curves and to one point per cube there, the surfaces kept the
// voxels' steps and thin triangles (docs/benchmarks.md); smoothed as
// anywhere else, with a point per sheet, every label stays within the voxel
// tolerance.
TEST(JunctionBands, TouchingOrgansOnThreeMillimetresAreSmoothWhereTheyMeet) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("totalseg_example_seg_fast_force_split.nii.gz");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto result = run_pipeline(path, MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  std::vector<double> shares;
  double smallest_angle = 180;
  size_t delivered = 0;
  for (const auto& s : result->surfaces) {
    if (!s.is_output) continue;
    ++delivered;
    EXPECT_TRUE(s.fidelity->within_tolerance()) << s.label;
    smallest_angle = std::min(smallest_angle, s.statistics.min_angle_deg);
    const auto* label = result->input.statistics.find(s.label);
    if (label != nullptr && label->voxels >= 1000 && s.axis_aligned_share)
      shares.push_back(*s.axis_aligned_share);
  }
  EXPECT_EQ(delivered, 61u);
  ASSERT_EQ(shares.size(), 41u);
  std::nth_element(shares.begin(), shares.begin() + 20, shares.end());
  EXPECT_LT(shares[20], 0.095);
  EXPECT_GT(smallest_angle, 10);
  // The spleen, whose neighbours lie a voxel away along much of it: few of
  // its triangles meet at a sharp bend.
  const auto spleen = std::find_if(result->surfaces.begin(), result->surfaces.end(),
                                   [](const auto& s) { return s.is_output && s.label == 1; });
  ASSERT_NE(spleen, result->surfaces.end());
  EXPECT_LT(share_of_sharp_edges(spleen->mesh, 30), 0.06);
  // Faces parted across gaps a voxel wide do not pass through each other.
  const auto volume = volume::read_label_volume(path, {}, {});
  ASSERT_THAT(volume, testing::IsOk());
  conforming::InterfaceFigures figures;
  auto net = conforming::label_interfaces(*volume, {}, net_interface_params(NetOptions{}), figures);
  EXPECT_TRUE(conforming::crossings_after_taking_back_slides(net).empty());
}

// Cubes with a corner among the joined voxels keep one point: all joined,
// the net is the one with one point per cube; half joined, the gap's faces
// part only in the other half, and stay closed surfaces there too.
TEST(JunctionBands, JoinedVoxelsKeepOnePointInTheirCubes) {
  const auto volume = ball_with_a_cube_across_its_gap(0);
  auto params = net_interface_params(NetOptions{});
  conforming::InterfaceFigures figures;
  const size_t parted = conforming::label_interfaces(volume, {}, params, figures).points.size();
  params.split_sheets = false;
  const size_t one_per_cube =
      conforming::label_interfaces(volume, {}, params, figures).points.size();
  params.split_sheets = true;
  const auto& d = volume.geometry.dims;
  for (uint64_t i = 0; i < uint64_t(d[0] * d[1] * d[2]); ++i) params.joined_voxels.push_back(i);
  EXPECT_EQ(conforming::label_interfaces(volume, {}, params, figures).points.size(), one_per_cube);
  params.joined_voxels.clear();
  for (int64_t z = 0; z < d[2] / 2; ++z)
    for (int64_t y = 0; y < d[1]; ++y)
      for (int64_t x = 0; x < d[0]; ++x) params.joined_voxels.push_back((z * d[1] + y) * d[0] + x);
  const auto half = conforming::label_interfaces(volume, {}, params, figures);
  EXPECT_GT(half.points.size(), one_per_cube + (parted - one_per_cube) / 4);
  EXPECT_LT(half.points.size(), parted - (parted - one_per_cube) / 4);
  EXPECT_TRUE(surface::crossing_triangles(half.points, half.triangles).empty());
  // The gap leans the same way along x and y, and another way along z:
  // joining the quarter below along x or y gives as many points, along z
  // not.
  const auto joined_below = [&](int axis) {
    params.joined_voxels.clear();
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y)
        for (int64_t x = 0; x < d[0]; ++x)
          if (std::array<int64_t, 3>{x, y, z}[axis] < d[axis] / 4)
            params.joined_voxels.push_back((z * d[1] + y) * d[0] + x);
    return conforming::label_interfaces(volume, {}, params, figures).points.size();
  };
  EXPECT_EQ(joined_below(0), joined_below(1));
  EXPECT_NE(joined_below(0), joined_below(2));
  for (const int32_t label : {1, 2}) {
    const auto statistics = surface::compute_surface_statistics(
        conforming::net_label_surface(half, label, volume.geometry).mesh);
    EXPECT_TRUE(statistics.closed) << label;
    EXPECT_TRUE(statistics.manifold) << label;
  }
}

// On the frog smoothed without the volume step's pauses, a few faces parted
// across gaps pass through each other, which no label's own check would
// see: its net is made again with one point in the cubes around them, where
// they cannot, and keeps its parted points elsewhere. With the pauses none
// cross, and the net is made once.
TEST(JunctionBands, PartedFacesThatCrossAreJoinedAgain) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto path = testing::shared_data("frogtissue.mhd");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  const auto volume = volume::read_label_volume(path, {}, {});
  ASSERT_THAT(volume, testing::IsOk());
  const auto labels = testing::label_values(*volume);
  conforming::InterfaceFigures figures;
  auto params = net_interface_params(NetOptions{});
  const auto crossing_pairs = [](conforming::InterfaceSurface& net) {
    return crossings_between_labels(net, conforming::crossings_after_taking_back_slides(net));
  };
  auto paused = conforming::label_interfaces(*volume, labels, params, figures);
  EXPECT_EQ(crossing_pairs(paused), 0u);
  params.volume_pauses = 0;
  auto parted = conforming::label_interfaces(*volume, labels, params, figures);
  EXPECT_GT(crossing_pairs(parted), 0u);
  params.split_sheets = false;
  const size_t one_per_cube =
      conforming::label_interfaces(*volume, labels, params, figures).points.size();
  ASSERT_GT(parted.points.size(), one_per_cube + 1000);
  std::vector<StageTiming> stages;
  MeshParams without_pauses;
  without_pauses.net.volume_pauses = 0;
  auto nets = build_label_nets({*volume}, std::vector<size_t>(labels.size(), 0), labels,
                               without_pauses, {}, stages);
  ASSERT_THAT(nets, testing::IsOk());
  EXPECT_EQ(crossings_between_labels(nets->nets[0], nets->crossings[0]), 0u);
  // Nearly all the parted points are kept.
  const size_t kept = nets->nets[0].points.size() - one_per_cube;
  EXPECT_GT(kept, 0.95 * double(parted.points.size() - one_per_cube))
      << kept << " of " << parted.points.size() - one_per_cube;
}

}  // namespace
}  // namespace labelmesh
