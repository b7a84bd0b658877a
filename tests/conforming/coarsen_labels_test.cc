// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/coarsen_labels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/conforming/check_conforming_mesh.h"
#include "core/conforming/conforming_mesher.h"
#include "core/util/vec3.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/phantom_grid.h"
#include "support/label_volumes.h"
#include "support/status_matchers.h"

namespace labelmesh::conforming {
namespace {

using testing::label_volumes;

// A box of 6 x 4 x 3 voxels (label 2) inside a 10 x 10 x 10 grid.
volume::LabelVolume box() {
  const auto grid =
      volume::centred_grid({10, 10, 10}, {1, 1, 1}, testing::kIdentityDirection, {0, 0, 0});
  return volume::rasterise(grid, [&](const std::array<double, 3>& p) {
    const auto i = grid.to_index(p);
    const bool inside = std::lround(i[0]) >= 2 && std::lround(i[0]) < 8 && std::lround(i[1]) >= 3 &&
                        std::lround(i[1]) < 7 && std::lround(i[2]) >= 4 && std::lround(i[2]) < 7;
    return inside ? 2 : 0;
  });
}

TEST(CoarsenLabels, CountsTheFacesBetweenLabelsAndPicksBlocksThatFit) {
  const auto volume = box();
  const Coarsening kept = choose_coarsening(volume, {}, 0);
  EXPECT_EQ(kept.interface_faces, 2u * (6 * 4 + 4 * 3 + 6 * 3));
  EXPECT_EQ(kept.factors, (std::array<double, 3>{1, 1, 1}));
  EXPECT_EQ(choose_coarsening(volume, {}, 108).factors, (std::array<double, 3>{1, 1, 1}));
  // A quarter of the faces: blocks twice the voxel along each axis.
  EXPECT_EQ(choose_coarsening(volume, {}, 27).factors, (std::array<double, 3>{2, 2, 2}));
  // Unselected labels are outside: no faces at all.
  EXPECT_EQ(choose_coarsening(volume, {7}, 0).interface_faces, 0u);
}

TEST(CoarsenLabels, SpacingDecidesTheBlocksOnAnAnisotropicGrid) {
  auto volume = box();
  volume.geometry.spacing = {0.5, 0.5, 2};
  const Coarsening coarsening = choose_coarsening(volume, {}, 27);
  // Twice the smallest spacing: 1 mm blocks in-plane, and the thick axis kept.
  EXPECT_EQ(coarsening.factors, (std::array<double, 3>{2, 2, 1}));
}

TEST(CoarsenLabels, EachCoarserVoxelTakesTheNearestVoxelsLabel) {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kNestedSpheres);
  const auto& fine_geometry = phantom.volume.geometry;
  for (double factor : {2.0, 1.5}) {
    SCOPED_TRACE(factor);
    auto coarse = coarsen_labels(phantom.volume, {}, {factor, factor, factor}, RunContext{});
    ASSERT_THAT(coarse, testing::IsOk());
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(coarse->geometry.dims[a],
                static_cast<int64_t>(std::ceil(fine_geometry.dims[a] / factor)));
      EXPECT_DOUBLE_EQ(coarse->geometry.spacing[a], factor * fine_geometry.spacing[a]);
    }
    // Both grids start at the same outer corner.
    const auto corner = fine_geometry.to_physical({-0.5, -0.5, -0.5});
    EXPECT_NEAR(
        geometry::norm(geometry::sub(coarse->geometry.to_physical({-0.5, -0.5, -0.5}), corner)), 0,
        1e-9);
    const auto fine_volumes = label_volumes(phantom.volume);
    const auto coarse_volumes = label_volumes(*coarse);
    ASSERT_EQ(coarse_volumes.size(), 3u);
    // The inner ball is three to four coarser voxels in radius: which voxel
    // centres fall inside it sways its volume most.
    for (const auto& [label, volume] : fine_volumes) {
      const double tolerance = label == 1 ? 0.15 : 0.06;
      EXPECT_NEAR(coarse_volumes.at(label) / volume, 1.0, tolerance) << "label " << label;
    }
  }
  EXPECT_EQ(coarsen_labels(phantom.volume, {}, {0.5, 1, 1}, RunContext{}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(CoarsenLabels, TheMesherCoarsensWhenTheInterfacesWouldBeTooLarge) {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kNestedSpheres);
  ConformingParams params;
  ConformingFigures fine_figures, coarse_figures;
  volume_mesh::ImproveFigures improve;
  auto fine = mesh_conforming(phantom.volume, {}, params, RunContext{}, fine_figures, improve);
  ASSERT_THAT(fine, testing::IsOk());
  EXPECT_EQ(fine_figures.coarsening.factors, (std::array<double, 3>{1, 1, 1}));
  params.max_interface_faces = fine_figures.coarsening.interface_faces / 3;
  auto coarse = mesh_conforming(phantom.volume, {}, params, RunContext{}, coarse_figures, improve);
  ASSERT_THAT(coarse, testing::IsOk());
  for (double factor : coarse_figures.coarsening.factors) EXPECT_NEAR(factor, std::sqrt(3.0), 0.01);
  EXPECT_THAT(check_conforming_mesh(*coarse), testing::IsOk());
  EXPECT_LT(coarse->tetrahedra.size(), fine->tetrahedra.size() / 2);
  // Volumes are still measured against the input's voxels.
  for (const auto& label : coarse_figures.labels)
    EXPECT_LT(std::abs(label.volume_change()), 0.06) << "label " << label.label;
}

}  // namespace
}  // namespace labelmesh::conforming
