// SPDX-License-Identifier: AGPL-3.0-or-later
// Each written file reads back, through readers we did not write, with the
// same counts.
#include "core/surface/write_surface.h"

#include <CGAL/IO/OFF.h>
#include <CGAL/Simple_cartesian.h>
#include <gtest/gtest.h>

#include <fstream>

#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkFieldData.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkStringArray.h>
#include <vtkXMLMultiBlockDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include "core/surface/extract_surfaces.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::surface {
namespace {

TriangleMesh torus_surface() {
  const auto phantom = volume::make_phantom(volume::PhantomShape::kTorus);
  const auto stats = volume::compute_label_statistics(phantom.volume);
  auto surfaces = extract_surfaces(phantom.volume, stats, {1}, RunContext{});
  EXPECT_THAT(surfaces, testing::IsOk());
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
  ASSERT_THAT(write_surface(mesh, path, format), testing::IsOk());
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

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Each file says its frame and label where its format has room, as 3D Slicer
// reads them, and holds RAS coordinates when asked.
TEST(WriteSurface, FilesSayTheirFrameAndLabel) {
  static const TriangleMesh mesh = torus_surface();
  const SurfaceFileInfo info{5, "Liver", CoordinateFrame::kRas};
  const auto dir = testing::scratch_dir("write-surface-frame");
  auto path_for = [&](SurfaceFormat format) {
    return (dir / (std::string("liver.") + std::string(surface_format_name(format)))).string();
  };
  for (auto format : all_surface_formats())
    ASSERT_THAT(write_surface(mesh, path_for(format), format, info), testing::IsOk());

  EXPECT_EQ(read_bytes(path_for(SurfaceFormat::kStl)).substr(0, 33),
            "SPACE=RAS labelmesh label 5 Liver");
  const std::string ply = read_bytes(path_for(SurfaceFormat::kPly));
  EXPECT_NE(ply.find("comment SPACE=RAS\n"), std::string::npos);
  EXPECT_NE(ply.find("comment labelmesh label 5 Liver\n"), std::string::npos);
  const std::string obj = read_bytes(path_for(SurfaceFormat::kObj));
  EXPECT_EQ(
      obj.rfind("# SPACE=RAS\n# labelmesh label 5 Liver\no label5-liver\ng label5-liver\n", 0), 0u);

  vtkNew<vtkOBJReader> obj_reader;
  obj_reader->SetFileName(path_for(SurfaceFormat::kObj).c_str());
  obj_reader->Update();
  double p[3];
  obj_reader->GetOutput()->GetPoint(7, p);
  // VTK reads OBJ coordinates as floats.
  EXPECT_NEAR(p[0], -mesh.points[7][0], 1e-5);
  EXPECT_NEAR(p[1], -mesh.points[7][1], 1e-5);
  EXPECT_NEAR(p[2], mesh.points[7][2], 1e-5);

  vtkNew<vtkXMLPolyDataReader> vtp_reader;
  vtp_reader->SetFileName(path_for(SurfaceFormat::kVtp).c_str());
  vtp_reader->Update();
  vtkPolyData* polydata = vtp_reader->GetOutput();
  polydata->GetPoint(7, p);
  EXPECT_EQ(p[0], -mesh.points[7][0]);
  auto* labels = vtkIntArray::SafeDownCast(polydata->GetCellData()->GetArray("label"));
  ASSERT_NE(labels, nullptr);
  EXPECT_EQ(labels->GetNumberOfValues(), vtkIdType(mesh.triangles.size()));
  EXPECT_EQ(labels->GetRange()[0], 5);
  EXPECT_EQ(labels->GetRange()[1], 5);
  auto* name = vtkStringArray::SafeDownCast(polydata->GetFieldData()->GetAbstractArray("name"));
  auto* space = vtkStringArray::SafeDownCast(polydata->GetFieldData()->GetAbstractArray("SPACE"));
  ASSERT_TRUE(name && space);
  EXPECT_EQ(name->GetValue(0), "Liver");
  EXPECT_EQ(space->GetValue(0), "RAS");
}

TEST(WriteSurface, TheSceneHasOneNamedBlockPerLabel) {
  static const TriangleMesh torus = torus_surface();
  TriangleMesh moved = torus;
  for (auto& p : moved.points) p[0] += 100;
  const auto dir = testing::scratch_dir("write-surface-scene");
  const auto path = (dir / "surfaces.vtm").string();
  ASSERT_TRUE(write_surface_scene(
                  {&torus, &moved},
                  {{1, "Liver", CoordinateFrame::kLps}, {7, "", CoordinateFrame::kLps}}, path)
                  .ok());
  vtkNew<vtkXMLMultiBlockDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  auto* scene = vtkMultiBlockDataSet::SafeDownCast(reader->GetOutput());
  ASSERT_NE(scene, nullptr);
  ASSERT_EQ(scene->GetNumberOfBlocks(), 2u);
  EXPECT_STREQ(scene->GetMetaData(0u)->Get(vtkCompositeDataSet::NAME()), "label 1 Liver");
  EXPECT_STREQ(scene->GetMetaData(1u)->Get(vtkCompositeDataSet::NAME()), "label 7");
  auto* second = vtkPolyData::SafeDownCast(scene->GetBlock(1));
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(second->GetNumberOfPolys(), vtkIdType(moved.triangles.size()));
  double p[3];
  second->GetPoint(3, p);
  EXPECT_EQ(p[0], moved.points[3][0]);
  auto* labels = vtkIntArray::SafeDownCast(second->GetCellData()->GetArray("label"));
  ASSERT_NE(labels, nullptr);
  EXPECT_EQ(labels->GetValue(0), 7);
}

TEST(WriteSurface, UnwritablePathIsAnError) {
  const auto status = write_surface(torus_surface(), "/nonexistent/dir/x.vtp", SurfaceFormat::kVtp);
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInternal));
  EXPECT_NE(std::string(status.message()).find("/nonexistent/dir/x.vtp"), std::string::npos);
}

}  // namespace
}  // namespace labelmesh::surface
