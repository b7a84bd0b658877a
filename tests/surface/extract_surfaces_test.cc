// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/extract_surfaces.h"

#include <gtest/gtest.h>

#include <cmath>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include "core/surface/surface_statistics.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/read_label_volume.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::surface {
namespace {

using volume::make_phantom;
using volume::PhantomShape;

std::vector<LabelSurface> extract_all(const volume::LabelVolume& v) {
  const auto stats = volume::compute_label_statistics(v);
  std::vector<int32_t> labels;
  for (const auto& l : stats.labels) labels.push_back(l.label);
  auto surfaces = extract_surfaces(v, stats, labels, RunContext{});
  EXPECT_THAT(surfaces, testing::IsOk());
  return surfaces.ok() ? std::move(*surfaces) : std::vector<LabelSurface>{};
}

void expect_closed_manifold(const SurfaceStatistics& s) {
  EXPECT_TRUE(s.closed);
  EXPECT_TRUE(s.manifold);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.non_manifold_edges, 0u);
  EXPECT_EQ(s.non_manifold_vertices, 0u);
  EXPECT_GT(s.volume_mm3, 0) << "surface must face outwards";
}

TEST(ExtractSurfaces, SphereEnclosesItsAnalyticVolume) {
  const auto phantom = make_phantom(PhantomShape::kSphere);
  const auto surfaces = extract_all(phantom.volume);
  ASSERT_EQ(surfaces.size(), 1u);
  const auto s = compute_surface_statistics(surfaces[0].mesh);
  expect_closed_manifold(s);
  EXPECT_EQ(s.euler_characteristic, 2);
  EXPECT_EQ(s.components, 1u);
  EXPECT_NEAR(s.volume_mm3 / phantom.truth[0].volume_mm3, 1.0, 0.02);
}

TEST(ExtractSurfaces, TorusHasGenusOne) {
  const auto phantom = make_phantom(PhantomShape::kTorus);
  const auto surfaces = extract_all(phantom.volume);
  ASSERT_EQ(surfaces.size(), 1u);
  const auto s = compute_surface_statistics(surfaces[0].mesh);
  expect_closed_manifold(s);
  EXPECT_EQ(s.euler_characteristic, 0);
  EXPECT_NEAR(s.volume_mm3 / phantom.truth[0].volume_mm3, 1.0, 0.02);
}

TEST(ExtractSurfaces, NestedShellsHaveTwoBoundaries) {
  const auto phantom = make_phantom(PhantomShape::kNestedSpheres);
  const auto surfaces = extract_all(phantom.volume);
  ASSERT_EQ(surfaces.size(), 3u);
  const int expected_euler[3] = {2, 4, 4};  // ball, then two shells (inner + outer sphere)
  for (size_t i = 0; i < 3; ++i) {
    const auto s = compute_surface_statistics(surfaces[i].mesh);
    expect_closed_manifold(s);
    EXPECT_EQ(s.euler_characteristic, expected_euler[i]) << "label " << surfaces[i].label;
    EXPECT_NEAR(s.volume_mm3 / phantom.truth[i].volume_mm3, 1.0, 0.03)
        << "label " << surfaces[i].label;
  }
}

TEST(ExtractSurfaces, TouchingBoxesKeepTheirVolumes) {
  const auto phantom = make_phantom(PhantomShape::kTouchingBoxes);
  const auto surfaces = extract_all(phantom.volume);
  ASSERT_EQ(surfaces.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const auto s = compute_surface_statistics(surfaces[i].mesh);
    expect_closed_manifold(s);
    EXPECT_NEAR(s.volume_mm3 / phantom.truth[i].volume_mm3, 1.0, 0.01);
  }
}

TEST(ExtractSurfaces, ObliqueVerticesLieOnVoxelFaces) {
  // Every Marching Cubes vertex is halfway between two voxel centres: mapped
  // back through the header's geometry, one index coordinate is k + 1/2 and
  // the other two are whole.
  const auto phantom = make_phantom(PhantomShape::kObliqueEllipsoid);
  const auto surfaces = extract_all(phantom.volume);
  ASSERT_EQ(surfaces.size(), 1u);
  const auto& g = phantom.volume.geometry;
  for (const auto& p : surfaces[0].mesh.points) {
    const auto index = g.to_index(p);
    int halves = 0, wholes = 0;
    for (double c : index) {
      const double frac = c - std::floor(c);
      if (std::abs(frac - 0.5) < 1e-6) ++halves;
      if (frac < 1e-6 || frac > 1 - 1e-6) ++wholes;
    }
    ASSERT_EQ(halves, 1) << index[0] << " " << index[1] << " " << index[2];
    ASSERT_EQ(wholes, 2);
  }
  const auto s = compute_surface_statistics(surfaces[0].mesh);
  expect_closed_manifold(s);
  EXPECT_NEAR(s.volume_mm3 / phantom.truth[0].volume_mm3, 1.0, 0.02);
}

volume::LabelVolume filled_cube(int n, bool fill_all) {
  volume::LabelVolume v;
  v.geometry.dims = {n, n, n};
  auto labels = vtkSmartPointer<vtkUnsignedCharArray>::New();
  labels->SetNumberOfTuples(int64_t{n} * n * n);
  labels->FillValue(0);
  if (fill_all) {
    labels->FillValue(1);
  } else {
    labels->SetValue(0, 1);
  }
  v.voxels = vtkSmartPointer<vtkImageData>::New();
  v.voxels->SetDimensions(n, n, n);
  v.voxels->GetPointData()->SetScalars(labels);
  return v;
}

TEST(ExtractSurfaces, LabelsTouchingTheVolumeEdgeAreClosed) {
  for (int n : {2, 3}) {
    const auto surfaces = extract_all(filled_cube(n, true));
    ASSERT_EQ(surfaces.size(), 1u);
    const auto s = compute_surface_statistics(surfaces[0].mesh);
    expect_closed_manifold(s);
    EXPECT_EQ(s.euler_characteristic, 2);
  }
}

TEST(ExtractSurfaces, SingleVoxelIsAnOctahedron) {
  const auto surfaces = extract_all(filled_cube(2, false));
  ASSERT_EQ(surfaces.size(), 1u);
  const auto s = compute_surface_statistics(surfaces[0].mesh);
  EXPECT_EQ(s.nodes, 6u);
  EXPECT_EQ(s.triangles, 8u);
  EXPECT_NEAR(s.volume_mm3, 1.0 / 6.0, 1e-12);  // octahedron with unit diagonals
}

TEST(ExtractSurfaces, AbsentLabelIsAnError) {
  const auto v = filled_cube(2, false);
  const auto stats = volume::compute_label_statistics(v);
  const auto result = extract_surfaces(v, stats, {9}, RunContext{});
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kInvalidArgument));
}

void expect_volumes_match_voxels(const std::string& file, uint64_t min_voxels, double tolerance) {
  auto v = volume::read_label_volume(testing::shared_data(file), {}, RunContext{});
  ASSERT_THAT(v, testing::IsOk());
  const auto stats = volume::compute_label_statistics(*v);
  const auto surfaces = extract_all(*v);
  ASSERT_EQ(surfaces.size(), stats.labels.size());
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const auto s = compute_surface_statistics(surfaces[i].mesh);
    EXPECT_TRUE(s.closed) << file << " label " << surfaces[i].label;
    EXPECT_GT(s.volume_mm3, 0) << file << " label " << surfaces[i].label;
    if (stats.labels[i].voxels < min_voxels) continue;
    const double voxel_volume = double(stats.labels[i].voxels) * v->geometry.voxel_volume();
    EXPECT_NEAR(s.volume_mm3 / voxel_volume, 1.0, tolerance)
        << file << " label " << surfaces[i].label;
  }
}

TEST(ExtractSurfacesRealData, LiverSurfacesAreClosedManifoldAndKeepVolume) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  auto v = volume::read_label_volume(testing::shared_data("liver.inr.gz"), {}, RunContext{});
  ASSERT_THAT(v, testing::IsOk());
  const auto stats = volume::compute_label_statistics(*v);
  const auto surfaces = extract_all(*v);
  ASSERT_EQ(surfaces.size(), 4u);
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const auto s = compute_surface_statistics(surfaces[i].mesh);
    expect_closed_manifold(s);
    if (stats.labels[i].voxels < 1000) continue;
    const double voxel_volume = double(stats.labels[i].voxels) * v->geometry.voxel_volume();
    EXPECT_NEAR(s.volume_mm3 / voxel_volume, 1.0, 0.01) << "label " << surfaces[i].label;
  }
}

TEST(ExtractSurfacesRealData, MirroredAxesStillFaceOutwards) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  // x and y flipped in the header (a negative-determinant grid).
  expect_volumes_match_voxels("totalseg_example_seg_mr.nii.gz", 10000, 0.03);
}

}  // namespace
}  // namespace labelmesh::surface
