// SPDX-License-Identifier: AGPL-3.0-or-later
// The report names the build that made it and the frame of its coordinates.
#include "core/pipeline/report.h"

#include <gtest/gtest.h>

#include "absl/strings/match.h"

namespace labelmesh {
namespace {

TEST(Report, NamesTheBuildThatMadeIt) {
  const v1::Report report = make_report(MeshResult{}, MeshParams{});
  EXPECT_EQ(report.labelmesh_version(), LABELMESH_VERSION);
  EXPECT_FALSE(report.build().compiler().empty());
  EXPECT_TRUE(absl::StartsWith(report.build().cgal_version(), "5.5"))
      << report.build().cgal_version();
  EXPECT_TRUE(absl::StartsWith(report.build().vtk_version(), "9.1"))
      << report.build().vtk_version();
#ifdef NDEBUG
  EXPECT_EQ(report.build().build_type(), "release");
#else
  EXPECT_EQ(report.build().build_type(), "debug");
#endif
#ifdef __SANITIZE_ADDRESS__
  ASSERT_EQ(report.build().sanitizers_size(), 1);
  EXPECT_EQ(report.build().sanitizers(0), "address");
#endif
  EXPECT_EQ(report.input().convention(), kPatientConvention);
}

}  // namespace
}  // namespace labelmesh
