// SPDX-License-Identifier: AGPL-3.0-or-later
// Each written volume mesh reads back, through readers we did not write (VTK's XML reader and
// meshio), with the same counts, labels and positive orientation; the Abaqus file is checked
// line by line against C3D4's conventions.
#include "core/volume_mesh/write_volume_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "core/volume_mesh/tetrahedralize.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume_mesh {
namespace {

using Point = std::array<double, 3>;

// The cube [lo, lo + 10]³ with each side split into a 4x4 grid of squares (192 triangles, 98
// points), wound outwards. Fine enough that TetGen can refine inside while keeping it.
surface::TriangleMesh cube(Point lo) {
  constexpr int kCells = 4;
  constexpr double kSize = 10;
  surface::TriangleMesh mesh;
  std::map<Point, uint32_t> index;
  const auto point = [&](const Point& p) {
    const auto [it, added] = index.emplace(p, uint32_t(mesh.points.size()));
    if (added) mesh.points.push_back(p);
    return it->second;
  };
  // Each side: a corner and two edge directions whose cross product points out of the cube.
  struct Side {
    Point origin, u, v;
  };
  const Side sides[6] = {{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}}, {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},
                         {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},
                         {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (const Side& side : sides) {
    const auto at = [&](int i, int j) {
      Point p;
      for (int k = 0; k < 3; ++k) {
        p[k] = lo[k] + kSize * (side.origin[k] + (side.u[k] * i + side.v[k] * j) / kCells);
      }
      return point(p);
    };
    for (int i = 0; i < kCells; ++i) {
      for (int j = 0; j < kCells; ++j) {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  }
  return mesh;
}

// Two 10 mm cubes side by side, [0,10]x[0,10]x[0,10] with label 1 and [10,20]x[0,10]x[0,10]
// with label 2, meshed separately (so they share no points), refined to at most 20 mm³.
const TetMesh& two_labels() {
  static const TetMesh mesh = [] {
    TetMesh both;
    for (int32_t label : {1, 2}) {
      TetgenFigures figures;
      TetgenParams params;
      params.max_volume_mm3 = 20;
      auto piece =
          tetrahedralize(cube({10.0 * (label - 1), 0, 0}), label, params, RunContext{}, figures);
      EXPECT_THAT(piece, testing::IsOk());
      if (piece.ok()) both.append(*piece);
    }
    return both;
  }();
  return mesh;
}

std::vector<double> qualities(const TetMesh& mesh) {
  std::vector<double> values;
  for (size_t i = 0; i < mesh.tetrahedra.size(); ++i) values.push_back(0.25 + 0.001 * i);
  return values;
}

size_t count_label(const TetMesh& mesh, int32_t label) {
  return size_t(std::count(mesh.labels.begin(), mesh.labels.end(), label));
}

std::string path_in(const std::filesystem::path& dir, VolumeFormat format) {
  return (dir / (std::string("two-labels.") + std::string(volume_format_name(format)))).string();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What meshio sees in a file, one "key values..." line each.
std::map<std::string, std::string> meshio_summary(const std::filesystem::path& dir,
                                                  const std::string& path) {
  const auto script = (dir / "summary.py").string();
  std::ofstream(script) << R"(import sys
import meshio
import numpy as np
m = meshio.read(sys.argv[1])
print("points", len(m.points))
for kind in ("tetra", "triangle"):
    print(kind, sum(len(b.data) for b in m.cells if b.type == kind))
volumes = [np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6
           for p in (m.points[b.data] for b in m.cells if b.type == "tetra")]
if volumes:
    volumes = np.concatenate(volumes)
    print("min_volume", volumes.min())
    print("total_volume", volumes.sum())
for key in ("gmsh:physical", "gmsh:geometrical", "medit:ref", "tetgen:ref"):
    for block, data in zip(m.cells, m.cell_data.get(key, [])):
        print(block.type + ":" + key, *sorted(set(int(x) for x in np.asarray(data).ravel())))
for key in ("label", "interface", "label_inside", "label_outside"):
    if key in m.cell_data:
        print("values:" + key, *sorted(set(int(x) for d in m.cell_data[key] for x in np.asarray(d).ravel())))
if "quality" in m.cell_data:
    print("quality_sum", sum(float(np.sum(d)) for d in m.cell_data["quality"]))
for name, cells in sorted(m.cell_sets.items()):
    print("cell_set:" + name, sum(len(c) for c in cells))
for name, points in sorted(m.point_sets.items()):
    print("point_set:" + name, len(points))
for name in sorted(m.field_data):
    print("field:" + name, *m.field_data[name])
print("point0", *(repr(float(x)) for x in m.points[0]))
)";
  const std::string command = "/usr/bin/python3 " + script + " " + path + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  std::string output;
  if (pipe != nullptr) {
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
    EXPECT_EQ(pclose(pipe), 0) << output;
  }
  std::map<std::string, std::string> summary;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    const auto space = line.find(' ');
    summary[line.substr(0, space)] = space == std::string::npos ? "" : line.substr(space + 1);
  }
  return summary;
}

void expect_meshio_counts(const std::map<std::string, std::string>& summary, const TetMesh& mesh) {
  ASSERT_TRUE(summary.count("points")) << "meshio could not read the file";
  EXPECT_EQ(summary.at("points"), std::to_string(mesh.points.size()));
  EXPECT_EQ(summary.at("tetra"), std::to_string(mesh.tetrahedra.size()));
  EXPECT_GT(std::stod(summary.at("min_volume")), 0.0);
  EXPECT_NEAR(std::stod(summary.at("total_volume")), 2000, 1e-9 * 2000);
}

TEST(WriteVolumeMesh, FormatNamesRoundTrip) {
  ASSERT_EQ(all_volume_formats().size(), 6u);
  std::set<std::string_view> names;
  for (VolumeFormat format : all_volume_formats()) {
    names.insert(volume_format_name(format));
    EXPECT_EQ(volume_format_from_name(volume_format_name(format)), format);
  }
  EXPECT_EQ(names, (std::set<std::string_view>{"vtu", "msh", "mesh", "inp", "node", "xdmf"}));
  EXPECT_FALSE(volume_format_from_name("vtk").has_value());
  EXPECT_FALSE(volume_format_from_name("").has_value());
}

TEST(WriteVolumeMesh, TheTwoLabelMeshIsWhatTheTestsExpect) {
  const TetMesh& mesh = two_labels();
  ASSERT_GT(count_label(mesh, 1), 50u);  // the volume bound refines the cubes
  ASSERT_GT(count_label(mesh, 2), 50u);
  ASSERT_EQ(count_label(mesh, 1) + count_label(mesh, 2), mesh.tetrahedra.size());
  // Each label's boundary is its cube's 192 triangles, kept by keep_boundary.
  const auto faces = label_boundary_faces(mesh);
  EXPECT_EQ(faces.size(), 384u);
  for (const auto& face : faces) EXPECT_EQ(face.label, mesh.labels[face.tet]);
}

TEST(WriteVolumeMesh, VtuReadsBackWithLabelsAndQuality) {
  const TetMesh& mesh = two_labels();
  const auto quality = qualities(mesh);
  const auto dir = testing::scratch_dir("write-volume-vtu");
  const auto path = path_in(dir, VolumeFormat::kVtu);
  ASSERT_THAT(write_volume_mesh(mesh, quality, path, VolumeFormat::kVtu), testing::IsOk());

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfPoints(), vtkIdType(mesh.points.size()));
  ASSERT_EQ(grid->GetNumberOfCells(), vtkIdType(mesh.tetrahedra.size()));
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
    EXPECT_EQ(grid->GetCellType(c), VTK_TETRA);
  double p[3];
  grid->GetPoint(5, p);
  EXPECT_EQ(p[0], mesh.points[5][0]);
  EXPECT_EQ(p[2], mesh.points[5][2]);
  auto* labels = vtkIntArray::SafeDownCast(grid->GetCellData()->GetArray("label"));
  ASSERT_NE(labels, nullptr);
  ASSERT_EQ(labels->GetNumberOfValues(), vtkIdType(mesh.labels.size()));
  for (size_t i = 0; i < mesh.labels.size(); ++i)
    EXPECT_EQ(labels->GetValue(vtkIdType(i)), mesh.labels[i]);
  vtkDataArray* read_quality = grid->GetCellData()->GetArray("quality");
  ASSERT_NE(read_quality, nullptr);
  for (size_t i = 0; i < quality.size(); ++i)
    EXPECT_EQ(read_quality->GetTuple1(vtkIdType(i)), quality[i]);

  const auto summary = meshio_summary(dir, path);
  expect_meshio_counts(summary, mesh);
}

TEST(WriteVolumeMesh, MshCarriesLabelsAsPhysicalTags) {
  const TetMesh& mesh = two_labels();
  const auto quality = qualities(mesh);
  const auto dir = testing::scratch_dir("write-volume-msh");
  const auto path = path_in(dir, VolumeFormat::kMsh);
  ASSERT_THAT(write_volume_mesh(mesh, quality, path, VolumeFormat::kMsh), testing::IsOk());
  const std::string text = read_text(path);
  EXPECT_EQ(text.rfind("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", 0), 0u);
  EXPECT_NE(text.find("$PhysicalNames\n2\n3 1 \"label_1\"\n3 2 \"label_2\"\n"), std::string::npos);

  const auto summary = meshio_summary(dir, path);
  expect_meshio_counts(summary, mesh);
  EXPECT_EQ(summary.at("tetra:gmsh:physical"), "1 2");
  EXPECT_EQ(summary.at("tetra:gmsh:geometrical"), "1 2");
  ASSERT_TRUE(summary.count("quality_sum"));
  double expected_sum = 0;
  for (double q : quality) expected_sum += q;
  EXPECT_NEAR(std::stod(summary.at("quality_sum")), expected_sum, 1e-9 * expected_sum);
}

TEST(WriteVolumeMesh, MeditCarriesLabelsAsRefsWithOutwardBoundaries) {
  const TetMesh& mesh = two_labels();
  const auto dir = testing::scratch_dir("write-volume-mesh");
  const auto path = path_in(dir, VolumeFormat::kMedit);
  ASSERT_THAT(write_volume_mesh(mesh, {}, path, VolumeFormat::kMedit), testing::IsOk());
  const auto summary = meshio_summary(dir, path);
  expect_meshio_counts(summary, mesh);
  EXPECT_EQ(summary.at("tetra:medit:ref"), "1 2");
  EXPECT_EQ(summary.at("triangle"), "384");
  EXPECT_EQ(summary.at("triangle:medit:ref"), "1 2");

  // Every boundary triangle lies on its cube's surface and its normal points out of the cube.
  std::istringstream text(read_text(path));
  std::string word;
  while (text >> word && word != "Triangles") {
  }
  size_t count = 0;
  text >> count;
  ASSERT_EQ(count, 384u);
  for (size_t i = 0; i < count; ++i) {
    uint32_t v[3];
    int ref;
    text >> v[0] >> v[1] >> v[2] >> ref;
    ASSERT_TRUE(text);
    const Point& a = mesh.points[v[0] - 1];
    const Point& b = mesh.points[v[1] - 1];
    const Point& c = mesh.points[v[2] - 1];
    const Point n{(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                  (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                  (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
    const Point centre{10.0 * (ref - 1) + 5, 5, 5};
    const Point centroid{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3,
                         (a[2] + b[2] + c[2]) / 3};
    double outward = 0;
    for (int k = 0; k < 3; ++k) outward += n[k] * (centroid[k] - centre[k]);
    EXPECT_GT(outward, 0) << "triangle " << i;
  }
}

TEST(WriteVolumeMesh, TetgenNodeAndEleCarryLabelsAsRegions) {
  const TetMesh& mesh = two_labels();
  const auto dir = testing::scratch_dir("write-volume-node");
  const auto path = path_in(dir, VolumeFormat::kTetgen);
  ASSERT_THAT(write_volume_mesh(mesh, {}, path, VolumeFormat::kTetgen), testing::IsOk());
  EXPECT_TRUE(std::filesystem::exists(dir / "two-labels.ele"));
  const auto summary = meshio_summary(dir, path);
  expect_meshio_counts(summary, mesh);
  EXPECT_EQ(summary.at("tetra:tetgen:ref"), "1 2");
}

// CalculiX reads at most 20 characters a field: a coordinate a rounding
// from zero, whose shortest exact form takes 23, is written within 20 and
// reads back to within 1e-13 of it; ordinary ones keep their exact form.
TEST(WriteVolumeMesh, AbaqusCoordinatesFitCalculixFields) {
  TetMesh mesh = two_labels();
  mesh.points[0][1] = -1.1314057027034252e-05;
  mesh.points[1][2] = 26.14549617436983;
  const auto dir = testing::scratch_dir("write-volume-inp-fields");
  const auto path = path_in(dir, VolumeFormat::kAbaqus);
  ASSERT_THAT(write_volume_mesh(mesh, {}, path, VolumeFormat::kAbaqus), testing::IsOk());
  std::istringstream text(read_text(path));
  std::string line;
  bool in_nodes = false;
  size_t node_lines = 0;
  std::map<long, Point> nodes;
  while (std::getline(text, line)) {
    if (line.rfind('*', 0) == 0) {
      in_nodes = line == "*NODE";
      continue;
    }
    if (!in_nodes) continue;
    ++node_lines;
    std::istringstream fields(line);
    std::string field;
    long id = 0;
    Point p{};
    for (int k = 0; std::getline(fields, field, ','); ++k) {
      const auto first = field.find_first_not_of(' ');
      EXPECT_LE(field.size() - first, 20u) << line;
      if (k == 0)
        id = std::stol(field);
      else
        p[k - 1] = std::stod(field);
    }
    nodes[id] = p;
  }
  ASSERT_EQ(node_lines, mesh.points.size());
  EXPECT_NEAR(nodes.at(1)[1], -1.1314057027034252e-05, 1e-13);
  EXPECT_EQ(nodes.at(2)[2], 26.14549617436983);
}

// The C3D4 node order and face numbers, independently of the writer: the Jacobian of
// u = (1-g-h-r)u1 + g u2 + h u3 + r u4 is det[p2-p1, p3-p1, p4-p1] (CalculiX shape4tet.f), and
// faces are S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1.
TEST(WriteVolumeMesh, AbaqusElementsArePositiveAndSurfacesLieOnTheBoundary) {
  const TetMesh& mesh = two_labels();
  const auto dir = testing::scratch_dir("write-volume-inp");
  const auto path = path_in(dir, VolumeFormat::kAbaqus);
  ASSERT_THAT(write_volume_mesh(mesh, {}, path, VolumeFormat::kAbaqus), testing::IsOk());

  std::map<long, Point> nodes;
  std::map<long, std::array<long, 4>> elements;
  std::map<long, std::string> element_set;
  std::map<std::string, std::vector<std::pair<long, int>>> surfaces;
  std::map<std::string, std::set<long>> node_sets;
  std::istringstream text(read_text(path));
  std::string line, section, name;
  size_t element_keywords = 0;
  while (std::getline(text, line)) {
    if (line.rfind("**", 0) == 0) continue;
    if (line.rfind('*', 0) == 0) {
      section = line.substr(0, line.find(','));
      const auto equals = line.rfind('=');
      name = equals == std::string::npos ? "" : line.substr(equals + 1);
      if (section == "*ELEMENT") {
        ++element_keywords;
        EXPECT_NE(line.find("TYPE=C3D4"), std::string::npos) << line;
      }
      continue;
    }
    for (char& c : line) c = c == ',' ? ' ' : c;
    std::istringstream fields(line);
    if (section == "*NODE") {
      long id;
      Point p;
      fields >> id >> p[0] >> p[1] >> p[2];
      ASSERT_TRUE(fields) << line;
      nodes[id] = p;
    } else if (section == "*ELEMENT") {
      long id;
      std::array<long, 4> n;
      fields >> id >> n[0] >> n[1] >> n[2] >> n[3];
      ASSERT_TRUE(fields) << line;
      elements[id] = n;
      element_set[id] = name;
    } else if (section == "*NSET") {
      long id;
      while (fields >> id) node_sets[name].insert(id);
    } else if (section == "*SURFACE") {
      long id;
      std::string face;
      fields >> id >> face;
      ASSERT_TRUE(fields) << line;
      ASSERT_EQ(face.size(), 2u);
      ASSERT_EQ(face[0], 'S');
      surfaces[name].push_back({id, face[1] - '0'});
    }
  }
  EXPECT_EQ(element_keywords, 2u);
  ASSERT_EQ(nodes.size(), mesh.points.size());
  ASSERT_EQ(elements.size(), mesh.tetrahedra.size());

  for (const auto& [id, n] : elements) {
    const Point& p1 = nodes.at(n[0]);
    Point e[3];
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) e[i][k] = nodes.at(n[i + 1])[k] - p1[k];
    }
    const double jacobian = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                            e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                            e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    EXPECT_GT(jacobian, 0) << "element " << id;
    EXPECT_EQ(element_set.at(id), "LABEL_" + std::to_string(mesh.labels[size_t(id - 1)]));
  }

  const int face_nodes[5][3] = {{}, {0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
  ASSERT_EQ(surfaces.size(), 2u);
  for (int label : {1, 2}) {
    const std::string prefix = "LABEL_" + std::to_string(label);
    const auto& faces = surfaces[prefix + "_SURFACE"];
    EXPECT_EQ(faces.size(), 192u) << prefix;
    std::set<long> surface_nodes;
    for (const auto& [id, number] : faces) {
      ASSERT_GE(number, 1);
      ASSERT_LE(number, 4);
      EXPECT_EQ(element_set.at(id), prefix);
      // The face's three nodes share one coordinate that is on the cube's surface.
      const auto& n = elements.at(id);
      const double lo[3] = {10.0 * (label - 1), 0, 0};
      bool on_a_side = false;
      for (int k = 0; k < 3; ++k) {
        for (double plane : {lo[k], lo[k] + 10}) {
          bool all = true;
          for (int f : face_nodes[number]) all = all && nodes.at(n[f])[k] == plane;
          on_a_side = on_a_side || all;
        }
      }
      EXPECT_TRUE(on_a_side) << prefix << " element " << id << " S" << number;
      for (int f : face_nodes[number]) surface_nodes.insert(n[f]);
    }
    EXPECT_EQ(node_sets[prefix + "_BOUNDARY"], surface_nodes) << prefix;
    EXPECT_EQ(surface_nodes.size(), 98u) << prefix;
  }

  const auto summary = meshio_summary(dir, path);
  expect_meshio_counts(summary, mesh);
  EXPECT_EQ(summary.at("cell_set:LABEL_1"), std::to_string(count_label(mesh, 1)));
  EXPECT_EQ(summary.at("cell_set:LABEL_2"), std::to_string(count_label(mesh, 2)));
  EXPECT_EQ(summary.at("point_set:LABEL_1_BOUNDARY"), "98");
}

// Label names and the RAS frame reach every format: group names that solvers and meshio read,
// comments and field data that say the frame, coordinates with x and y negated and no element
// turned inside out.
TEST(WriteVolumeMesh, NamesAndTheFrameReachEveryFormat) {
  const TetMesh& mesh = two_labels();
  VolumeFileInfo info;
  info.label_names = {{1, "Liver"}, {2, "Right kidney (\"RK\")"}};
  info.frame = CoordinateFrame::kRas;
  EXPECT_EQ(label_group_name(1, info), "label_1_liver");
  EXPECT_EQ(label_group_name(2, info), "label_2_right_kidney_rk");
  EXPECT_EQ(label_group_name(3, info), "label_3");
  const auto dir = testing::scratch_dir("write-volume-names");
  const Point& first = mesh.points[0];
  for (VolumeFormat format : all_volume_formats()) {
    SCOPED_TRACE(std::string(volume_format_name(format)));
    const auto path = path_in(dir, format);
    ASSERT_THAT(write_volume_mesh(mesh, {}, path, format, info), testing::IsOk());
    const auto summary = meshio_summary(dir, path);
    expect_meshio_counts(summary, mesh);
    std::istringstream point0(summary.at("point0"));
    double x = 0, y = 0, z = 0;
    point0 >> x >> y >> z;
    EXPECT_EQ(x, -first[0]);
    EXPECT_EQ(y, -first[1]);
    EXPECT_EQ(z, first[2]);
    const std::string text = format == VolumeFormat::kVtu ? "" : read_text(path);
    switch (format) {
      case VolumeFormat::kMsh:
        EXPECT_EQ(summary.at("field:label_1_liver"), "1 3");
        EXPECT_EQ(summary.at("field:label_2_right_kidney_rk"), "2 3");
        break;
      case VolumeFormat::kAbaqus:
        EXPECT_NE(text.find("SPACE=RAS"), std::string::npos);
        EXPECT_EQ(summary.at("cell_set:LABEL_1_LIVER"), std::to_string(count_label(mesh, 1)));
        EXPECT_EQ(summary.at("cell_set:LABEL_2_RIGHT_KIDNEY_RK"),
                  std::to_string(count_label(mesh, 2)));
        EXPECT_EQ(summary.at("point_set:LABEL_2_RIGHT_KIDNEY_RK_BOUNDARY"), "98");
        EXPECT_NE(text.find("*SURFACE, TYPE=ELEMENT, NAME=LABEL_1_LIVER_SURFACE"),
                  std::string::npos);
        break;
      case VolumeFormat::kMedit:
        EXPECT_NE(text.find("# labelmesh: coordinates in mm, SPACE=RAS\n"), std::string::npos);
        EXPECT_NE(text.find("# ref 2: label_2_right_kidney_rk\n"), std::string::npos);
        break;
      case VolumeFormat::kTetgen:
        EXPECT_NE(text.find("SPACE=RAS"), std::string::npos);
        break;
      case VolumeFormat::kXdmf:
        EXPECT_NE(text.find("<!-- labelmesh: coordinates in mm, SPACE=RAS -->"), std::string::npos);
        EXPECT_NE(text.find("<!-- label 2: label_2_right_kidney_rk -->"), std::string::npos);
        EXPECT_EQ(summary.at("values:label"), "1 2");
        break;
      case VolumeFormat::kVtu: {
        EXPECT_EQ(summary.at("field:label_1_liver"), "1");
        EXPECT_EQ(summary.at("field:label_2_right_kidney_rk"), "2");
        EXPECT_EQ(summary.at("field:SPACE=RAS"), "1");
        break;
      }
    }
  }
}

// XDMF for dolfinx: the labels as cell tags and quality beside them; the
// interfaces in a second file as facet tags, on the same points.
TEST(WriteVolumeMesh, XdmfCarriesCellTagsAndFacetTags) {
  const TetMesh& mesh = two_labels();
  const auto quality = qualities(mesh);
  const auto faces = interface_faces(mesh);
  const auto pairs = interface_pairs(faces);
  ASSERT_EQ(pairs.size(), 2u);  // two cubes apart: each one's outer boundary
  VolumeFileInfo info;
  info.interfaces = &faces;
  const auto dir = testing::scratch_dir("write-volume-xdmf");
  const auto path = path_in(dir, VolumeFormat::kXdmf);
  ASSERT_THAT(write_volume_mesh(mesh, quality, path, VolumeFormat::kXdmf, info), testing::IsOk());

  const auto cells = meshio_summary(dir, path);
  expect_meshio_counts(cells, mesh);
  EXPECT_EQ(cells.at("values:label"), "1 2");
  double quality_sum = 0;
  for (double q : quality) quality_sum += q;
  EXPECT_NEAR(std::stod(cells.at("quality_sum")), quality_sum, 1e-9 * quality_sum);

  const auto facets_path = facets_xdmf_path(path);
  EXPECT_EQ(facets_path, (dir / "two-labels_facets.xdmf").string());
  const auto facets = meshio_summary(dir, facets_path);
  EXPECT_EQ(facets.at("points"), std::to_string(mesh.points.size()));
  EXPECT_EQ(facets.at("triangle"), std::to_string(faces.size()));
  EXPECT_EQ(facets.at("values:interface"), "1 2");
  EXPECT_EQ(facets.at("values:label_inside"), "1 2");
  EXPECT_EQ(facets.at("values:label_outside"), "0");
  const std::string text = read_text(facets_path);
  EXPECT_NE(text.find("<!-- interface 2: label_2__outside -->"), std::string::npos)
      << text.substr(0, 400);
}

TEST(WriteVolumeMesh, BadInputsAndPathsAreErrorsNamingTheFile) {
  const TetMesh& mesh = two_labels();
  const auto dir = testing::scratch_dir("write-volume-errors");
  const std::string msh = (dir / "x.msh").string();

  const auto short_quality = write_volume_mesh(mesh, {1.0}, msh, VolumeFormat::kMsh);
  EXPECT_THAT(short_quality, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_EQ(std::string(short_quality.message()).rfind(msh + ": ", 0), 0u) << short_quality;

  TetMesh unlabelled = mesh;
  unlabelled.labels[3] = 0;
  for (VolumeFormat format : {VolumeFormat::kMsh, VolumeFormat::kAbaqus}) {
    const std::string path = path_in(dir, format);
    const auto status = write_volume_mesh(unlabelled, {}, path, format);
    EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << status;
    EXPECT_EQ(std::string(status.message()).rfind(path + ": label 0", 0), 0u) << status;
  }
  // Zero is fine where nothing needs a positive tag.
  EXPECT_TRUE(
      write_volume_mesh(unlabelled, {}, path_in(dir, VolumeFormat::kVtu), VolumeFormat::kVtu).ok());

  TetMesh broken = mesh;
  broken.tetrahedra[0][2] = uint32_t(mesh.points.size());
  EXPECT_EQ(write_volume_mesh(broken, {}, msh, VolumeFormat::kMsh).code(),
            absl::StatusCode::kInvalidArgument);
  broken = mesh;
  broken.labels.pop_back();
  EXPECT_EQ(write_volume_mesh(broken, {}, msh, VolumeFormat::kVtu).code(),
            absl::StatusCode::kInvalidArgument);

  const std::string not_node = (dir / "x.ele").string();
  EXPECT_EQ(write_volume_mesh(mesh, {}, not_node, VolumeFormat::kTetgen).code(),
            absl::StatusCode::kInvalidArgument);

  for (VolumeFormat format : all_volume_formats()) {
    const std::string path = "/nonexistent/dir/x." + std::string(volume_format_name(format));
    const auto status = write_volume_mesh(mesh, {}, path, format);
    EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInternal)) << status;
    EXPECT_NE(std::string(status.message()).find("/nonexistent/dir/x."), std::string::npos)
        << status;
  }
}

}  // namespace
}  // namespace labelmesh::volume_mesh
