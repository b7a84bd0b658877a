// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/output_names.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/pipeline/pipeline.h"
#include "core/pipeline/write_results.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

TEST(OutputNames, SlugsKeepLettersAndDigitsOnly) {
  EXPECT_EQ(name_slug("Liver"), "liver");
  EXPECT_EQ(name_slug("Left kidney (L2)"), "left-kidney-l2");
  EXPECT_EQ(name_slug("../../etc/passwd"), "etc-passwd");
  EXPECT_EQ(name_slug("  vertebrae_L5 "), "vertebrae-l5");
  EXPECT_EQ(name_slug("!!!"), "");
  EXPECT_EQ(name_slug(std::string(100, 'a')).size(), 48u);
  EXPECT_EQ(name_slug(std::string(47, 'a') + " b"), std::string(47, 'a'));
}

TEST(OutputNames, UnnamedLabelsKeepTheirNumberOnly) {
  volume::LabelDescriptions names{volume::named_label(5, "Liver"), volume::named_label(6, "%%")};
  EXPECT_EQ(surface_file_stem(5, names), "surface-label5-liver");
  EXPECT_EQ(surface_file_stem(6, names), "surface-label6");
  EXPECT_EQ(surface_file_stem(7, names), "surface-label7");
}

TEST(OutputNames, ADicomSegSegmentNamesItsSurfaceFiles) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto out = testing::scratch_dir("named-outputs");
  MeshParams params;
  auto result =
      run_pipeline(testing::shared_data("dicom-seg/dcmqi-24x38x3-seg.dcm"), params, RunContext{});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_THAT(write_results(*result, params, out.string(), RunContext{}), testing::IsOk());
  EXPECT_TRUE(std::filesystem::exists(out / "surface-label1-liver.stl"));
  EXPECT_TRUE(std::filesystem::exists(out / "surface-label1-liver.vtp"));
  EXPECT_FALSE(std::filesystem::exists(out / "surface-label1.stl"));
}

}  // namespace
}  // namespace labelmesh
