// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/conforming_mesher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "core/conforming/check_conforming_mesh.h"
#include "core/conforming/label_interfaces.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "support/status_matchers.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;
using volume::PhantomShape;

std::map<int32_t, uint64_t> voxel_counts(const volume::LabelVolume& volume) {
  std::map<int32_t, uint64_t> counts;
  for (const auto& label : volume::compute_label_statistics(volume).labels)
    counts[label.label] = label.voxels;
  return counts;
}

// Each label's enclosed volume, from the triangles it lies behind (as given)
// and in front of (reversed), by the divergence theorem.
std::map<int32_t, double> enclosed_volumes(const InterfaceSurface& surface) {
  std::map<int32_t, double> six_volumes;
  const Vec3& o = surface.points.front();
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    const double six = geometry::dot(geometry::sub(surface.points[tri[0]], o),
                                     geometry::cross(geometry::sub(surface.points[tri[1]], o),
                                                     geometry::sub(surface.points[tri[2]], o)));
    six_volumes[surface.sides[t][0]] += six;
    six_volumes[surface.sides[t][1]] -= six;
  }
  std::map<int32_t, double> volumes;
  for (const auto& [label, six] : six_volumes) {
    if (label != kOutside) volumes[label] = six / 6;
  }
  return volumes;
}

// Edges of `label`'s closed surface used an odd number of times.
size_t open_edges(const InterfaceSurface& surface, int32_t label) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    if (surface.sides[t][0] != label && surface.sides[t][1] != label) continue;
    const auto& tri = surface.triangles[t];
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(tri[k], tri[(k + 1) % 3])];
  }
  size_t open = 0;
  for (const auto& [edge, count] : uses) open += count % 2;
  return open;
}

TEST(LabelInterfaces, TheUnsmoothedNetIsTheVoxelStaircase) {
  const auto phantom = volume::make_phantom(PhantomShape::kNestedSpheres);
  InterfaceParams params;
  params.smoothing_rounds = 0;
  InterfaceFigures figures;
  const auto surface = label_interfaces(phantom.volume, {}, params, figures);
  ASSERT_GT(surface.triangles.size(), 1000u);
  EXPECT_EQ(figures.max_offset_mm, 0.0);
  for (const auto& sides : surface.sides) EXPECT_NE(sides[0], sides[1]);
  const auto voxels = voxel_counts(phantom.volume);
  const auto volumes = enclosed_volumes(surface);
  ASSERT_EQ(volumes.size(), 3u);
  const double voxel = phantom.volume.geometry.voxel_volume();
  for (const auto& [label, count] : voxels) {
    EXPECT_NEAR(volumes.at(label), count * voxel, 1e-9 * count * voxel) << "label " << label;
    EXPECT_EQ(open_edges(surface, label), 0u) << "label " << label;
  }
}

TEST(LabelInterfaces, SmoothedPointsStayWithinTheirVoxelCube) {
  const auto phantom = volume::make_phantom(PhantomShape::kNestedSpheres);
  InterfaceParams params;
  InterfaceFigures figures;
  const auto surface = label_interfaces(phantom.volume, {}, params, figures);
  const auto& s = phantom.volume.geometry.spacing;
  const double bound =
      0.5 * params.cube_fraction * std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  EXPECT_GT(figures.max_offset_mm, 0.1);
  EXPECT_LE(figures.max_offset_mm, bound + 1e-12);
  for (size_t p = 0; p < surface.points.size(); ++p) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(std::abs(surface.points[p][k] - surface.staircase[p][k]),
                0.5 * params.cube_fraction * s[k] + 1e-9);
    }
  }
  // Smoothing keeps each label's volume near its voxels' (Taubin, no shrinking).
  const auto voxels = voxel_counts(phantom.volume);
  const auto volumes = enclosed_volumes(surface);
  for (const auto& [label, count] : voxels) {
    const double voxel_volume = count * phantom.volume.geometry.voxel_volume();
    EXPECT_NEAR(volumes.at(label) / voxel_volume, 1.0, 0.03) << "label " << label;
    EXPECT_EQ(open_edges(surface, label), 0u);
  }
}

TEST(LabelInterfaces, ThickSlicesAreCutIntoShortEdges) {
  const auto phantom = volume::make_phantom(PhantomShape::kThinShapesAnisotropic);
  const auto& s = phantom.volume.geometry.spacing;
  ASSERT_GT(std::max({s[0], s[1], s[2]}), 3.5 * std::min({s[0], s[1], s[2]}));
  InterfaceParams params;
  params.smoothing_rounds = 0;
  InterfaceFigures figures;
  const auto surface = label_interfaces(phantom.volume, {}, params, figures);
  double longest = 0;
  for (const auto& tri : surface.triangles) {
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, geometry::norm(geometry::sub(surface.points[tri[k]],
                                                               surface.points[tri[(k + 1) % 3]])));
  }
  // Without cutting, edges along the slice axis would be a whole slice long.
  const double least = std::min({s[0], s[1], s[2]});
  EXPECT_LE(longest, 1.5 * std::sqrt(2.0) * least);
  const auto volumes = enclosed_volumes(surface);
  for (const auto& [label, count] : voxel_counts(phantom.volume)) {
    const double voxel_volume = count * phantom.volume.geometry.voxel_volume();
    EXPECT_NEAR(volumes.at(label), voxel_volume, 1e-9 * voxel_volume) << "label " << label;
    EXPECT_EQ(open_edges(surface, label), 0u);
  }
}

struct Meshed {
  volume_mesh::TetMesh mesh;
  ConformingFigures figures;
};

Meshed mesh_phantom(const volume::LabelVolume& volume, const std::vector<int32_t>& labels = {}) {
  Meshed meshed;
  volume_mesh::ImproveFigures improve;
  auto mesh =
      mesh_conforming(volume, labels, ConformingParams{}, RunContext{}, meshed.figures, improve);
  EXPECT_THAT(mesh, testing::IsOk());
  if (mesh.ok()) meshed.mesh = std::move(*mesh);
  return meshed;
}

TEST(ConformingMesher, NestedLabelsShareTheirInterfaces) {
  const auto phantom = volume::make_phantom(PhantomShape::kNestedSpheres);
  const auto [mesh, figures] = mesh_phantom(phantom.volume);
  const auto check = check_conforming_mesh(mesh);
  EXPECT_TRUE(check.ok()) << check.failures();
  EXPECT_EQ(check.interfaces, 3u);  // (1,2), (2,3), (3, outside)
  EXPECT_GT(check.interface_faces, 500u);
  EXPECT_LT(check.volume_gap_fraction(), 1e-9);
  EXPECT_EQ(figures.regions.mislabelled_faces, 0u);

  const auto pairs = volume_mesh::interface_pairs(volume_mesh::interface_faces(mesh));
  EXPECT_EQ(pairs, (std::vector<std::array<int32_t, 2>>{{1, 2}, {2, 3}, {3, 0}}));
  ASSERT_EQ(figures.labels.size(), 3u);
  for (const auto& label : figures.labels) {
    EXPECT_GT(label.tetrahedra, 0u);
    EXPECT_LT(std::abs(label.volume_change()), 0.03) << "label " << label.label;
  }
  const auto quality = volume_mesh::summarise_quality(mesh);
  EXPECT_GE(quality.min, 0.2);
  EXPECT_GE(quality.min_dihedral_deg, 10.0);
  EXPECT_EQ(quality.invalid, 0);
}

TEST(ConformingMesher, TouchingBoxesMeetOnOneFlatInterface) {
  const auto phantom = volume::make_phantom(PhantomShape::kTouchingBoxes);
  const auto [mesh, figures] = mesh_phantom(phantom.volume);
  const auto check = check_conforming_mesh(mesh);
  EXPECT_TRUE(check.ok()) << check.failures();
  EXPECT_EQ(check.interfaces, 3u);  // (1,2), (1, outside), (2, outside)
  for (const auto& label : figures.labels)
    EXPECT_LT(std::abs(label.volume_change()), 0.05) << "label " << label.label;
}

TEST(ConformingMesher, AMirroredGridKeepsEveryLabelOnItsSide) {
  auto phantom = volume::make_phantom(PhantomShape::kNestedSpheres);
  auto& d = phantom.volume.geometry.direction;
  for (int row = 0; row < 3; ++row) d[3 * row] = -d[3 * row];  // x runs the other way
  const auto [mesh, figures] = mesh_phantom(phantom.volume);
  EXPECT_THAT(check_conforming_mesh(mesh), testing::IsOk());
  for (const auto& label : figures.labels)
    EXPECT_LT(std::abs(label.volume_change()), 0.03) << "label " << label.label;
}

TEST(ConformingMesher, UnselectedLabelsAreOutside) {
  const auto phantom = volume::make_phantom(PhantomShape::kNestedSpheres);
  const auto [mesh, figures] = mesh_phantom(phantom.volume, {1, 3});
  EXPECT_THAT(check_conforming_mesh(mesh), testing::IsOk());
  EXPECT_EQ(std::set<int32_t>(mesh.labels.begin(), mesh.labels.end()), (std::set<int32_t>{1, 3}));
  // The shell of label 2 between them is a cavity left empty.
  EXPECT_GE(figures.regions.outside_regions, 1u);
}

TEST(ConformingMesher, RefusesAVolumeWithoutTheSelectedLabels) {
  const auto phantom = volume::make_phantom(PhantomShape::kSphere);
  ConformingFigures figures;
  volume_mesh::ImproveFigures improve;
  auto mesh =
      mesh_conforming(phantom.volume, {7}, ConformingParams{}, RunContext{}, figures, improve);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh, testing::StatusIs(absl::StatusCode::kInvalidArgument));
}

TEST(ConformityCheck, FindsWhatBreaksAMesh) {
  const auto phantom = volume::make_phantom(PhantomShape::kTouchingBoxes);
  const auto [mesh, figures] = mesh_phantom(phantom.volume);
  ASSERT_THAT(check_conforming_mesh(mesh), testing::IsOk());

  auto inverted = mesh;
  std::swap(inverted.tetrahedra[0][0], inverted.tetrahedra[0][1]);
  EXPECT_EQ(check_conforming_mesh(inverted).inverted_tetrahedra, 1u);

  auto overlapping = mesh;
  overlapping.tetrahedra.push_back(mesh.tetrahedra[10]);
  overlapping.labels.push_back(mesh.labels[10] == 1 ? 2 : 1);
  const auto overlap = check_conforming_mesh(overlapping);
  EXPECT_GE(overlap.overshared_faces, 1u);
  EXPECT_GT(overlap.volume_gap_fraction(), 1e-9);
  EXPECT_FALSE(overlap.ok());

  auto duplicated = mesh;
  duplicated.points.push_back(mesh.points[mesh.tetrahedra[5][2]]);
  duplicated.tetrahedra[5][2] = static_cast<uint32_t>(duplicated.points.size() - 1);
  const auto duplicate = check_conforming_mesh(duplicated);
  EXPECT_EQ(duplicate.duplicate_points, 1u);
  EXPECT_FALSE(duplicate.ok());

  auto unlabelled = mesh;
  unlabelled.labels[3] = 0;
  EXPECT_EQ(check_conforming_mesh(unlabelled).unlabelled_tetrahedra, 1u);
}

}  // namespace
}  // namespace labelmesh::conforming
