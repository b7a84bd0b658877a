// SPDX-License-Identifier: AGPL-3.0-or-later
// Labels resampled by nearest neighbour from a coarser grid are meshed on
// that grid: the surfaces follow the drawn shape instead of the blocks of
// pixels, and the report says which grid they were made on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/surface/voxel_fidelity.h"
#include "core/volume/read_label_volume.h"
#include "support/analytic_shapes.h"
#include "support/mesh_results.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

// `drawn` resampled by nearest neighbour to `pitch` times finer pixels
// along x and y, over the same extent.
volume::LabelVolume finer_pixels(const volume::LabelVolume& drawn, double pitch) {
  volume::LabelVolume fine;
  auto& g = fine.geometry;
  g = drawn.geometry;
  g.dims[0] = static_cast<int64_t>(std::floor(double(drawn.geometry.dims[0]) * pitch));
  g.dims[1] = static_cast<int64_t>(std::floor(double(drawn.geometry.dims[1]) * pitch));
  g.spacing[0] /= pitch;
  g.spacing[1] /= pitch;
  // The fine grid's first edge on the drawn grid's.
  g.origin[0] += 0.5 * (g.spacing[0] - drawn.geometry.spacing[0]);
  g.origin[1] += 0.5 * (g.spacing[1] - drawn.geometry.spacing[1]);
  const auto* from = static_cast<const uint8_t*>(drawn.voxels->GetScalarPointer());
  auto labels = vtkSmartPointer<vtkUnsignedCharArray>::New();
  labels->SetNumberOfTuples(g.voxel_count());
  const auto coarse = [pitch](int64_t i) {
    return static_cast<int64_t>(std::lround((double(i) + 0.5) / pitch - 0.5));
  };
  int64_t n = 0;
  const auto& d = drawn.geometry.dims;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x)
        labels->SetValue(n++, from[(z * d[1] + std::min(coarse(y), d[1] - 1)) * d[0] +
                                   std::min(coarse(x), d[0] - 1)]);
  fine.voxels = vtkSmartPointer<vtkImageData>::New();
  fine.voxels->SetDimensions(int(g.dims[0]), int(g.dims[1]), int(g.dims[2]));
  fine.voxels->GetPointData()->SetScalars(labels);
  return fine;
}

using testing::output_of;

TEST(DrawnGridPipeline, AnEllipsoidDrawnOnThreeMillimetresIsSmoothOnFinerPixels) {
  const auto shape = testing::ellipsoid_shape(24, 17, 13);
  const auto fine = finer_pixels(testing::sample_shape(shape, {3, 3, 2}), 3.072);
  auto drawn = run_pipeline_on_volume(fine, MeshParams{}, {});
  MeshParams on_file;
  on_file.mesh_on_drawn_grid = false;
  auto file = run_pipeline_on_volume(fine, on_file, {});
  ASSERT_THAT(drawn, testing::IsOk());
  ASSERT_THAT(file, testing::IsOk());
  ASSERT_TRUE(drawn->input.file_geometry.has_value());
  EXPECT_FALSE(file->input.file_geometry.has_value());
  EXPECT_NEAR(drawn->input.geometry.spacing[0], 3, 0.02);
  EXPECT_EQ(drawn->input.geometry.spacing[2], 2);
  const auto* ours = output_of(*drawn, 1);
  const auto* blocks = output_of(*file, 1);
  ASSERT_NE(ours, nullptr);
  ASSERT_NE(blocks, nullptr);
  EXPECT_TRUE(drawn->warnings.empty());
  const auto ours_error = testing::shape_error(ours->mesh, shape);
  const auto blocks_error = testing::shape_error(blocks->mesh, shape);
  // Faithful to the fine pixels the surface steps with the blocks.
  EXPECT_LT(ours_error.normal_p95_deg, 0.7 * blocks_error.normal_p95_deg)
      << ours_error.normal_p95_deg << " " << blocks_error.normal_p95_deg;
  EXPECT_LT(ours_error.rms_mm, blocks_error.rms_mm);
  const double ours_share = surface::axis_aligned_share(ours->mesh, fine.geometry);
  const double blocks_share = surface::axis_aligned_share(blocks->mesh, fine.geometry);
  EXPECT_LT(ours_share, 0.6 * blocks_share) << ours_share << " " << blocks_share;
  // The report gives the file's grid and the one meshed on.
  const auto report = make_report(*drawn, MeshParams{});
  EXPECT_EQ(report.input().dims(0), fine.geometry.dims[0]);
  ASSERT_EQ(report.input().meshed_spacing_size(), 3);
  EXPECT_NEAR(report.input().meshed_spacing(0), 3, 0.02);
  EXPECT_EQ(make_report(*file, on_file).input().meshed_spacing_size(), 0);
}

// The TotalSegmentator CT slab holds a 3 mm segmentation on 0.98 mm pixels:
// meshed on the drawn grid its organs lose the blocks.
TEST(DrawnGridPipeline, TheCtSlabIsMeshedOnItsDrawnGrid) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  auto result =
      run_pipeline(testing::shared_data("totalseg_example_seg_dicom.nii.gz"), MeshParams{}, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_TRUE(result->input.file_geometry.has_value());
  EXPECT_NEAR(result->input.geometry.spacing[0], 3, 0.05);
  EXPECT_NEAR(result->input.geometry.spacing[1], 3, 0.05);
  EXPECT_EQ(result->input.geometry.spacing[2], 2);
  EXPECT_TRUE(result->warnings.empty());
  std::vector<double> shares;
  for (const auto& label : result->input.statistics.labels) {
    const auto* s = output_of(*result, label.label);
    ASSERT_NE(s, nullptr) << label.label;
    if (label.voxels * 9 >= 1000)
      shares.push_back(surface::axis_aligned_share(s->mesh, *result->input.file_geometry));
  }
  ASSERT_GE(shares.size(), 20u);
  std::sort(shares.begin(), shares.end());
  // Median 31.6 % on the file's pixels, 13.7 % Slicer-like.
  EXPECT_LT(shares[shares.size() / 2], 0.18);
}

}  // namespace
}  // namespace labelmesh
