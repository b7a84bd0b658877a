// SPDX-License-Identifier: AGPL-3.0-or-later
// Each written file reads back, through readers we did not write, with the
// same counts.
#include "core/surface/write_surface.h"

#include <CGAL/IO/OFF.h>
#include <CGAL/Simple_cartesian.h>
#include <gtest/gtest.h>

#include <fstream>

#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkXMLPolyDataReader.h>

#include "core/surface/extract_surfaces.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "support/test_files.h"

namespace labelmesh::surface {
namespace {

TriangleMesh torus_surface() {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kTorus);
  const auto stats = volume::compute_label_statistics(phantom.volume);
  auto surfaces = extract_surfaces(phantom.volume, stats, {1}, RunContext{});
  EXPECT_TRUE(surfaces.ok());
  return (*surfaces)[0].mesh;
}

template <typename Reader>
std::pair<int64_t, int64_t> vtk_counts(const std::string& path) {
  vtkNew<Reader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return {reader->GetOutput()->GetNumberOfPoints(), reader->GetOutput()->GetNumberOfPolys()};
}

class WriteSurface : public ::testing::TestWithParam<SurfaceFormat> {};

TEST_P(WriteSurface, ReadsBackWithTheSameCounts) {
  static const TriangleMesh mesh = torus_surface();
  ASSERT_GT(mesh.triangles.size(), 1000u);
  const auto format = GetParam();
  const auto dir =
      testing::scratch_dir(std::string("write-") + std::string(surface_format_name(format)));
  const auto path =
      (dir / (std::string("torus.") + std::string(surface_format_name(format)))).string();
  ASSERT_TRUE(write_surface(mesh, path, format).ok());
  std::pair<int64_t, int64_t> counts{-1, -1};
  switch (format) {
    case SurfaceFormat::kStl:
      counts = vtk_counts<vtkSTLReader>(path);
      break;  // merges shared points
    case SurfaceFormat::kPly:
      counts = vtk_counts<vtkPLYReader>(path);
      break;
    case SurfaceFormat::kObj:
      counts = vtk_counts<vtkOBJReader>(path);
      break;
    case SurfaceFormat::kVtp:
      counts = vtk_counts<vtkXMLPolyDataReader>(path);
      break;
    case SurfaceFormat::kOff: {
      std::vector<CGAL::Simple_cartesian<double>::Point_3> points;
      std::vector<std::vector<std::size_t>> polygons;
      std::ifstream in(path);
      ASSERT_TRUE(CGAL::IO::read_OFF(in, points, polygons));
      counts = {int64_t(points.size()), int64_t(polygons.size())};
      ASSERT_NEAR(points[7].x(), mesh.points[7][0], 1e-12);
      break;
    }
  }
  EXPECT_EQ(counts.first, int64_t(mesh.points.size()));
  EXPECT_EQ(counts.second, int64_t(mesh.triangles.size()));
}

INSTANTIATE_TEST_SUITE_P(Formats, WriteSurface, ::testing::ValuesIn(all_surface_formats()),
                         [](const auto& info) {
                           return std::string(surface_format_name(info.param));
                         });

TEST(WriteSurface, UnwritablePathIsAnError) {
  const auto status = write_surface(torus_surface(), "/nonexistent/dir/x.vtp", SurfaceFormat::kVtp);
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal);
  EXPECT_NE(std::string(status.message()).find("/nonexistent/dir/x.vtp"), std::string::npos);
}

}  // namespace
}  // namespace labelmesh::surface
