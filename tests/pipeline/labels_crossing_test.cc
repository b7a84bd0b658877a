// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/labels_crossing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>

#include "core/pipeline/pipeline.h"
#include "core/volume/phantom.h"
#include "support/status_matchers.h"

namespace labelmesh {
namespace {

// A closed cube of side 2 * half around `centre`, wound outward, as a
// label's delivered surface made by `stage`.
SurfaceResult cube_surface(int32_t label, const std::string& stage,
                           const std::array<double, 3>& centre, double half) {
  SurfaceResult s;
  s.label = label;
  s.stage = stage;
  s.is_output = true;
  for (int i = 0; i < 8; ++i)
    s.mesh.points.push_back({centre[0] + ((i & 1) ? half : -half),
                             centre[1] + ((i & 2) ? half : -half),
                             centre[2] + ((i & 4) ? half : -half)});
  s.mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return s;
}

TEST(LabelsCrossing, ASurfaceMadeApartThatEntersANeighbourIsFound) {
  std::vector<SurfaceResult> surfaces{cube_surface(1, "net", {0, 0, 0}, 5),
                                      cube_surface(2, "net_lighter", {8, 1, 1}, 4)};
  const auto found = labels_crossing(surfaces);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].label, 2);
  EXPECT_EQ(found[0].other, 1);
  EXPECT_GE(found[0].triangle_pairs, 4u);
}

TEST(LabelsCrossing, SurfacesApartOrAllFromTheNetGiveNone) {
  // A voxel's gap between them: no crossing.
  EXPECT_TRUE(labels_crossing({cube_surface(1, "net", {0, 0, 0}, 5),
                               cube_surface(2, "poisson", {10.5, 0, 0}, 5)})
                  .empty());
  // Both cut from the shared net: not looked at (they share interfaces).
  EXPECT_TRUE(
      labels_crossing({cube_surface(1, "net", {0, 0, 0}, 5), cube_surface(2, "net", {8, 1, 1}, 4)})
          .empty());
  // Stages that are not delivered do not count.
  auto stage = cube_surface(2, "repaired", {8, 1, 1}, 4);
  stage.is_output = false;
  EXPECT_TRUE(labels_crossing({cube_surface(1, "net", {0, 0, 0}, 5), stage}).empty());
}

// Boxes that meet with no triangles crossing: a surface wholly inside
// another, which a crossing test cannot see.
TEST(LabelsCrossing, ASurfaceWhollyInsideAnotherCrossesNone) {
  EXPECT_TRUE(
      labels_crossing({cube_surface(1, "net", {0, 0, 0}, 5), cube_surface(2, "mask", {1, 1, 1}, 2)})
          .empty());
}

TEST(LabelsCrossing, TwoLabelsMadeApartThatCrossAreListedOnce) {
  const auto found = labels_crossing(
      {cube_surface(1, "poisson", {0, 0, 0}, 5), cube_surface(2, "mask", {8, 1, 1}, 4)});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].label, 1);
  EXPECT_EQ(found[0].other, 2);
  EXPECT_GE(found[0].triangle_pairs, 4u);
}

TEST(LabelsCrossing, EachOtherLabelIsNamedWithItsOwnPairs) {
  std::vector<SurfaceResult> surfaces{cube_surface(1, "net", {0, 0, 0}, 5),
                                      cube_surface(3, "net", {0, 20, 0}, 5),
                                      cube_surface(2, "mask", {0, 10, 0}, 6)};
  const auto found = labels_crossing(surfaces);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].label, 2);
  EXPECT_EQ(found[0].other, 1);
  EXPECT_EQ(found[1].label, 2);
  EXPECT_EQ(found[1].other, 3);
  EXPECT_GT(found[0].triangle_pairs, 0u);
  EXPECT_EQ(found[0].triangle_pairs, found[1].triangle_pairs);
}

TEST(LabelsCrossing, OnlyLabelsOfOneLayerAreTestedAgainstEachOther) {
  const std::vector<SurfaceResult> surfaces{cube_surface(1, "net", {0, 0, 0}, 5),
                                            cube_surface(2, "mask", {8, 1, 1}, 4)};
  EXPECT_TRUE(labels_crossing(surfaces, {{2, 1}, {1, 0}}).empty());
  // A label not listed is in layer 0.
  EXPECT_TRUE(labels_crossing(surfaces, {{2, 1}}).empty());
  EXPECT_EQ(labels_crossing(surfaces, {{2, 0}}).size(), 1u);
  const auto found = labels_crossing(surfaces, {{1, 1}, {2, 1}});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].label, 2);
  EXPECT_EQ(found[0].other, 1);
}

// On the thin shapes on 0.75 x 0.75 x 3 mm voxels some labels fall back to
// the meshed mask, made apart from their neighbours; where such a surface
// enters another label's, the run says so for that label (and --strict
// refuses the run, as for any warning).
TEST(LabelsCrossing, ARunWarnsOfEachCrossing) {
  auto volume = volume::make_phantom(volume::PhantomShape::kThinShapesAnisotropic).volume;
  auto result = run_pipeline_on_volume(std::move(volume), MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  const auto found = labels_crossing(result->surfaces);
  ASSERT_FALSE(found.empty());
  for (const auto& c : found) {
    const std::string named = "surface crosses label " + std::to_string(c.other) +
                              "'s: " + std::to_string(c.triangle_pairs) + " pair(s)";
    EXPECT_TRUE(std::any_of(
        result->warnings.begin(), result->warnings.end(),
        [&](const LabelWarning& w) { return w.label == c.label && w.reason.find(named) == 0; }))
        << c.label << " crossing " << c.other;
  }
}

// The same thin shapes twice, as two layers of overlapping segments (the
// second's labels 100 higher): labels made apart are tested against their
// own layer's, where they cross as in one layer, and not against the other
// layer's copies of the same voxels, which they cross everywhere.
TEST(LabelsCrossing, ARunOfSeveralLayersWarnsWithinEachLayer) {
  auto volume = volume::make_phantom(volume::PhantomShape::kThinShapesAnisotropic).volume;
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(volume.voxels);
  auto* scalars = copy->GetPointData()->GetScalars();
  for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
    if (scalars->GetTuple1(i) != 0) scalars->SetTuple1(i, scalars->GetTuple1(i) + 100);
  volume.more_layers.push_back(copy);
  auto result = run_pipeline_on_volume(std::move(volume), MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  size_t crossing_warnings = 0, in_first_layer = 0;
  for (const auto& w : result->warnings) {
    const auto at = w.reason.find("surface crosses label ");
    if (at != 0) continue;
    ++crossing_warnings;
    const int other = std::stoi(w.reason.substr(std::string("surface crosses label ").size()));
    EXPECT_EQ(w.label >= 100, other >= 100) << w.label << " crossing " << other;
    in_first_layer += w.label < 100;
  }
  // The second layer's copies cross each other as the first's do.
  EXPECT_GT(in_first_layer, 0u);
  EXPECT_EQ(crossing_warnings, 2 * in_first_layer);
}

}  // namespace
}  // namespace labelmesh
