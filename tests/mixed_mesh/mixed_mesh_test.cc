// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed-element meshes built by hand: the face tables against VTK's, well-formedness,
// conformity (shared faces, a quad against two triangles, duplicate points, a crack), quality and
// volume, and each written file read back by readers we did not write (VTK's XML reader, meshio,
// `gmsh -check`, CalculiX) with the same counts, labels and positive elements.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkHexahedron.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPyramid.h>
#include <vtkTetra.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWedge.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/mixed_faces.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/mixed_mesh/write_mixed_mesh.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::mixed_mesh {
namespace {

using Point = std::array<double, 3>;
using volume_mesh::VolumeFileInfo;
using volume_mesh::VolumeFormat;

constexpr double kNear = 1e-12;

// The unit cube [0,1]³ as points 0-7 in VTK_HEXAHEDRON order: 0-3 the bottom counter-clockwise
// seen from above, 4-7 above them.
MixedMesh unit_hexahedron() {
  MixedMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                 {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  mesh.add(CellType::kHexahedron, {0, 1, 2, 3, 4, 5, 6, 7}, 1);
  return mesh;
}

uint32_t add_point(MixedMesh& mesh, Point p) {
  mesh.points.push_back(p);
  return static_cast<uint32_t>(mesh.points.size() - 1);
}

// (a) [0,2]x[0,1]x[0,1] as two unit hexahedra sharing the face x = 1.
MixedMesh two_hexahedra() {
  MixedMesh mesh = unit_hexahedron();
  const uint32_t a = add_point(mesh, {2, 0, 0}), b = add_point(mesh, {2, 1, 0});
  const uint32_t c = add_point(mesh, {2, 1, 1}), d = add_point(mesh, {2, 0, 1});
  mesh.add(CellType::kHexahedron, {1, a, b, 2, 5, d, c, 6}, 1);
  return mesh;
}

// (b) The unit cube with a pyramid on its top face, apex 0.5 above the face's centre.
MixedMesh hexahedron_with_pyramid() {
  MixedMesh mesh = unit_hexahedron();
  const uint32_t apex = add_point(mesh, {0.5, 0.5, 1.5});
  mesh.add(CellType::kPyramid, {4, 5, 6, 7, apex}, 1);
  return mesh;
}

// Adds a wedge on the cube's face x = 1: triangles (1,0,0) (2,0,0) (1,0,1) at y = 0 and the same
// at y = 1, so the quad on x = 1 is shared. The y = 0 triangle winds clockwise seen from y = 1,
// as VTK_WEDGE wants.
void add_wedge(MixedMesh& mesh, int32_t label) {
  const uint32_t a = add_point(mesh, {2, 0, 0}), b = add_point(mesh, {2, 1, 0});
  mesh.add(CellType::kWedge, {1, a, 5, 2, b, 6}, label);
}

// (c) The unit cube with a wedge beside it.
MixedMesh hexahedron_with_wedge() {
  MixedMesh mesh = unit_hexahedron();
  add_wedge(mesh, 1);
  return mesh;
}

// All four types, conforming: the cube (label 1), the pyramid on its top (label 1), the wedge
// beside it (label 2) and a tetrahedron (label 3) on the pyramid's face x ≈ 0. Volume
// 1 + 1/6 + 1/2 + 1/12 = 1.75.
MixedMesh all_four_types() {
  MixedMesh mesh = hexahedron_with_pyramid();
  add_wedge(mesh, 2);
  const uint32_t tip = add_point(mesh, {-0.5, 0.5, 1.5});
  // The pyramid's face 7,4,apex winds out of the pyramid, towards `tip`.
  mesh.add(CellType::kTetra, {7, 4, 8, tip}, 3);
  return mesh;
}

VolumeFileInfo names() {
  VolumeFileInfo info;
  info.label_names = {{1, "Body"}, {2, "Side wedge"}, {3, "Tip"}};
  return info;
}

Point centroid(const MixedMesh& mesh, size_t cell) {
  Point sum{0, 0, 0};
  const int n = node_count(mesh.types[cell]);
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < 3; ++i) sum[i] += mesh.points[mesh.cells[cell][k]][i] / n;
  return sum;
}

Point cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

TEST(MixedMeshFaces, TablesAreVtksAndWindOutwards) {
  const auto expect_vtk = [](CellType type, auto face_array) {
    const auto faces = local_faces(type);
    for (size_t f = 0; f < faces.size(); ++f) {
      const vtkIdType* vtk = face_array(vtkIdType(f));
      for (int k = 0; k < faces[f].size; ++k)
        EXPECT_EQ(faces[f].nodes[k], vtk[k]) << "type " << int(type) << " face " << f;
      if (faces[f].size == 3 && type != CellType::kTetra) {
        EXPECT_EQ(vtk[3], -1);
      }
    }
  };
  expect_vtk(CellType::kHexahedron, vtkHexahedron::GetFaceArray);
  expect_vtk(CellType::kWedge, vtkWedge::GetFaceArray);
  expect_vtk(CellType::kPyramid, vtkPyramid::GetFaceArray);
  expect_vtk(CellType::kTetra, vtkTetra::GetFaceArray);
  EXPECT_EQ(local_faces(CellType::kHexahedron).size(), 6u);
  EXPECT_EQ(local_faces(CellType::kWedge).size(), 5u);
  EXPECT_EQ(local_faces(CellType::kPyramid).size(), 5u);
  EXPECT_EQ(local_faces(CellType::kTetra).size(), 4u);

  // On valid cells, each face's normal points away from the cell's centroid.
  const MixedMesh mesh = all_four_types();
  for (const CellFace& face : cell_faces(mesh)) {
    const Point& a = mesh.points[face.points[0]];
    const Point normal =
        cross(sub(mesh.points[face.points[1]], a), sub(mesh.points[face.points[face.size - 1]], a));
    EXPECT_GT(dot(normal, sub(a, centroid(mesh, face.cell))), 0)
        << "cell " << face.cell << " face " << int(face.local);
  }
}

TEST(MixedMeshCheck, RejectsMalformedMeshes) {
  const MixedMesh good = all_four_types();
  EXPECT_THAT(check_mixed_mesh(good), testing::IsOk());
  MixedMesh unused_slots = good;
  unused_slots.cells[3][7] = 999;  // a tetrahedron's fifth to eighth entries are not read
  EXPECT_THAT(check_mixed_mesh(unused_slots), testing::IsOk());

  MixedMesh bad = good;
  bad.labels.pop_back();
  EXPECT_EQ(check_mixed_mesh(bad).code(), absl::StatusCode::kInvalidArgument);
  bad = good;
  bad.cells.push_back({});
  EXPECT_EQ(check_mixed_mesh(bad).code(), absl::StatusCode::kInvalidArgument);
  bad = good;
  bad.cells[2][5] = uint32_t(good.points.size());
  const auto out_of_range = check_mixed_mesh(bad);
  EXPECT_THAT(out_of_range, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(out_of_range.message()).find("cell 2 names point 12"), std::string::npos)
      << out_of_range;
  bad = good;
  bad.cells[1][4] = bad.cells[1][0];  // the pyramid's apex on a base corner
  const auto repeated = check_mixed_mesh(bad);
  EXPECT_THAT(repeated, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(repeated.message()).find("twice"), std::string::npos) << repeated;
  bad = good;
  bad.types[0] = static_cast<CellType>(7);
  EXPECT_EQ(check_mixed_mesh(bad).code(), absl::StatusCode::kInvalidArgument);
}

void expect_conformity(const Conformity& c, size_t interior, size_t boundary, size_t nonconforming,
                       size_t duplicates, size_t open) {
  EXPECT_EQ(c.interior_faces, interior);
  EXPECT_EQ(c.boundary_faces, boundary);
  EXPECT_EQ(c.nonconforming_faces, nonconforming);
  EXPECT_EQ(c.duplicate_points, duplicates);
  EXPECT_EQ(c.open_boundary_edges, open);
  EXPECT_EQ(c.ok(), nonconforming == 0 && duplicates == 0 && open == 0);
}

TEST(MixedMeshConformity, TwoHexahedraShareAFace) {
  const MixedMesh mesh = two_hexahedra();
  ASSERT_THAT(check_mixed_mesh(mesh), testing::IsOk());
  expect_conformity(check_conformity(mesh), 1, 10, 0, 0, 0);
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_NEAR(q.volume_mm3, 2, kNear);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_EQ(q.jacobian_ratio_min, 1);
}

TEST(MixedMeshConformity, PyramidOnAHexahedron) {
  const MixedMesh mesh = hexahedron_with_pyramid();
  expect_conformity(check_conformity(mesh), 1, 9, 0, 0, 0);
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_NEAR(q.volume_mm3, 1 + 1.0 / 6, kNear);
  EXPECT_NEAR(cell_signed_volume(mesh, 1), 1.0 / 6, kNear);
  EXPECT_EQ(q.pyramids, 1u);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_NEAR(q.jacobian_ratio[1], 1, kNear);  // a square base: JR 1
  ASSERT_TRUE(q.pyramid_aspect_ratio_min.has_value());
  EXPECT_GT(*q.pyramid_aspect_ratio_min, 0.2);
}

TEST(MixedMeshConformity, WedgeBesideAHexahedron) {
  const MixedMesh mesh = hexahedron_with_wedge();
  expect_conformity(check_conformity(mesh), 1, 9, 0, 0, 0);
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_NEAR(q.volume_mm3, 1.5, kNear);
  EXPECT_NEAR(cell_signed_volume(mesh, 1), 0.5, kNear);
  EXPECT_EQ(q.wedges, 1u);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_NEAR(q.jacobian_ratio[1], 1, kNear);  // a right prism
  EXPECT_FALSE(q.pyramid_aspect_ratio_min.has_value());
  EXPECT_EQ(q.tetra_summary.count, 0);
}

// (d) The cube's top quad against two tetrahedra that split the pyramid above it along the
// diagonal 4-6: no face matches the quad, and each tetrahedron's bottom lies on three of its
// corners. The quad and both triangles are non-conforming; the rest of the boundary closes.
TEST(MixedMeshConformity, QuadAgainstTwoTrianglesIsNonconforming) {
  MixedMesh mesh = unit_hexahedron();
  const uint32_t apex = add_point(mesh, {0.5, 0.5, 1.5});
  mesh.add(CellType::kTetra, {4, 5, 6, apex}, 1);
  mesh.add(CellType::kTetra, {4, 6, 7, apex}, 1);
  const Conformity c = check_conformity(mesh);
  expect_conformity(c, 1, 9, 3, 0, 0);
  EXPECT_FALSE(c.ok());
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_NEAR(q.volume_mm3, 1 + 1.0 / 6, kNear);
}

// (e) A cube with its two layers swapped: every corner Jacobian is -1.
TEST(MixedMeshQuality, InvertedHexahedronIsInvalid) {
  MixedMesh mesh = unit_hexahedron();
  mesh.cells[0] = {4, 5, 6, 7, 0, 1, 2, 3};
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_EQ(q.invalid, 1u);
  EXPECT_LT(q.jacobian_ratio[0], 0);
  EXPECT_LT(q.jacobian_ratio_min, 0);
  EXPECT_EQ(q.cell_summary.invalid, 1);
  EXPECT_NEAR(q.volume_mm3, -1, kNear);
  // Its faces now wind inwards, but a lone cell still has a closed boundary.
  expect_conformity(check_conformity(mesh), 0, 6, 0, 0, 0);

  // A tetrahedron turned inside out: JR -1, Q negative.
  MixedMesh tetra;
  tetra.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetra.add(CellType::kTetra, {0, 2, 1, 3}, 1);
  const MixedQuality t = measure_mixed_mesh(tetra);
  EXPECT_EQ(t.invalid, 1u);
  EXPECT_EQ(t.jacobian_ratio[0], -1);
  EXPECT_LT(t.quality[0], 0);
  EXPECT_NEAR(t.volume_mm3, -1.0 / 6, kNear);
}

// (f) Two cubes meshed apart and put side by side: the four points of the face x = 1 are there
// twice. Each cube's boundary is closed on its own.
TEST(MixedMeshConformity, DuplicatePointsAreCounted) {
  MixedMesh mesh = unit_hexahedron();
  MixedMesh right = unit_hexahedron();
  for (auto& p : right.points) p[0] += 1;
  mesh.append(right);
  expect_conformity(check_conformity(mesh), 0, 12, 0, 4, 0);
}

// (g) Two cubes that share three points of their common face; the fourth is a duplicate in the
// right cube. The two faces no longer match, so the edges between the shared points carry four
// boundary faces each: a crack, an open boundary.
TEST(MixedMeshConformity, CrackOpensTheBoundary) {
  MixedMesh mesh = two_hexahedra();
  const uint32_t copy = add_point(mesh, mesh.points[5]);
  mesh.cells[1][4] = copy;  // the right cube's corner (1,0,1)
  ASSERT_THAT(check_mixed_mesh(mesh), testing::IsOk());
  const Conformity c = check_conformity(mesh);
  expect_conformity(c, 0, 12, 0, 1, 2);
  EXPECT_FALSE(c.ok());
}

TEST(MixedMeshQuality, AllFourTypes) {
  const MixedMesh mesh = all_four_types();
  expect_conformity(check_conformity(mesh), 3, 14, 0, 0, 0);
  const MixedQuality q = measure_mixed_mesh(mesh);
  EXPECT_EQ(q.hexahedra, 1u);
  EXPECT_EQ(q.pyramids, 1u);
  EXPECT_EQ(q.wedges, 1u);
  EXPECT_EQ(q.tetrahedra, 1u);
  ASSERT_EQ(q.jacobian_ratio.size(), 4u);
  ASSERT_EQ(q.quality.size(), 4u);
  for (double jr : q.jacobian_ratio) EXPECT_NEAR(jr, 1, kNear);
  EXPECT_NEAR(q.jacobian_ratio_min, 1, kNear);
  EXPECT_NEAR(q.jacobian_ratio_mean, 1, kNear);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_NEAR(q.volume_mm3, 1.75, kNear);
  EXPECT_NEAR(cell_signed_volume(mesh, 3), 1.0 / 12, kNear);
  // The tetrahedron's quality is its Q, the others' their JR.
  EXPECT_EQ(q.quality[3], quality::tetra_quality(
                              {mesh.points[7], mesh.points[4], mesh.points[8], mesh.points[11]}));
  EXPECT_GT(q.quality[3], 0.2);
  EXPECT_LT(q.quality[3], 1);
  EXPECT_EQ(q.quality[0], q.jacobian_ratio[0]);
  EXPECT_EQ(q.tetra_summary.count, 1);
  EXPECT_EQ(q.tetra_summary.min, q.quality[3]);
  EXPECT_GT(q.tetra_summary.min_dihedral_deg, 0);
  EXPECT_LT(q.tetra_summary.max_dihedral_deg, 180);
  EXPECT_EQ(q.cell_summary.count, 4);
  EXPECT_EQ(q.cell_summary.good, 4);
  ASSERT_TRUE(q.pyramid_aspect_ratio_min.has_value());
  EXPECT_EQ(*q.pyramid_aspect_ratio_min,
            quality::pyramid_signed_aspect_ratio(
                {mesh.points[4], mesh.points[5], mesh.points[6], mesh.points[7], mesh.points[8]}));
}

// The volume of a hexahedron with non-planar faces equals the integral of its trilinear map's
// Jacobian determinant, here by 3x3x3 Gauss points (exact: the determinant has degree ≤ 2 in
// each parameter).
TEST(MixedMeshQuality, VolumeOfAWarpedHexahedronIsExact) {
  MixedMesh mesh = unit_hexahedron();
  mesh.points[6] = {1.3, 1.2, 1.4};
  mesh.points[1] = {1.1, -0.2, 0.1};
  mesh.points[4] = {0.1, 0.05, 0.8};
  const double g[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  const double w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  double integral = 0;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) {
        const double t[3] = {g[a], g[b], g[c]};
        double J[3][3] = {};
        for (int n = 0; n < 8; ++n) {
          double shape[3];  // d(shape)/d(t_i)
          for (int i = 0; i < 3; ++i) {
            shape[i] = 1;
            for (int j = 0; j < 3; ++j) {
              const double f = corner[n][j] ? t[j] : 1 - t[j];
              shape[i] *= i == j ? (corner[n][j] ? 1 : -1) : f;
            }
          }
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) J[k][i] += mesh.points[n][k] * shape[i];
        }
        const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                           J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                           J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
        integral += w[a] * w[b] * w[c] * det;
      }
    }
  }
  EXPECT_NEAR(cell_signed_volume(mesh, 0), integral, 1e-12);
  EXPECT_NE(integral, 1);
}

// --- Files -----------------------------------------------------------------------------------

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs `command`; its exit status and combined output.
std::pair<int, std::string> run(const std::string& command) {
  std::string output;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {-1, output};
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  return {pclose(pipe), output};
}

// What meshio sees in a file, one "key values..." line each. Volumes are computed per cell in
// meshio's orderings (VTK's, but Gmsh's for wedges), by Gauss points exact for each type.
std::map<std::string, std::string> meshio_summary(const std::filesystem::path& dir,
                                                  const std::string& path) {
  const auto script = (dir / "summary.py").string();
  std::ofstream(script) << R"(import sys
import meshio
import numpy as np
m = meshio.read(sys.argv[1])
print("points", len(m.points))

def det(a, b, c):
    return np.einsum("ij,ij->i", a, np.cross(b, c))

def tetra(p):
    return det(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]) / 6

g = [0.5 - 0.5 / np.sqrt(3), 0.5 + 0.5 / np.sqrt(3)]

def hexahedron(p):
    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    v = 0
    for t in [(a, b, c) for a in g for b in g for c in g]:
        d = [0, 0, 0]
        for n, c in enumerate(corners):
            for i in range(3):
                s = 1.0
                for j in range(3):
                    f = t[j] if c[j] else 1 - t[j]
                    s *= (1 if c[j] else -1) if i == j else f
                d[i] = d[i] + s * p[:, n]
        v = v + det(*d) / 8
    return v

def wedge(p):  # Gmsh's prism: 0,1,2 counter-clockwise seen from 3,4,5
    v = 0
    for z in g:
        a = (1 - z) * (p[:, 1] - p[:, 0]) + z * (p[:, 4] - p[:, 3])
        b = (1 - z) * (p[:, 2] - p[:, 0]) + z * (p[:, 5] - p[:, 3])
        c = (p[:, 3] + p[:, 4] + p[:, 5] - p[:, 0] - p[:, 1] - p[:, 2]) / 3
        v = v + det(a, b, c) / 4
    return v

def pyramid(p):  # half the four corner tetrahedra: the volume over a planar base
    return sum(tetra(p[:, [i, (i + 1) % 4, (i + 3) % 4, 4]]) for i in range(4)) / 2

volume = {"tetra": tetra, "hexahedron": hexahedron, "wedge": wedge, "pyramid": pyramid}
total = 0
for kind in ("hexahedron", "wedge", "pyramid", "tetra", "triangle", "quad"):
    blocks = [b for b in m.cells if b.type == kind]
    print(kind, sum(len(b.data) for b in blocks))
    if kind in volume and blocks:
        v = np.concatenate([volume[kind](m.points[b.data]) for b in blocks])
        print("min_volume:" + kind, v.min())
        total += v.sum()
print("total_volume", total)
for key in ("gmsh:physical", "gmsh:geometrical", "medit:ref"):
    for block, data in zip(m.cells, m.cell_data.get(key, [])):
        print(block.type + ":" + key, *sorted(set(int(x) for x in np.asarray(data).ravel())))
for key in ("quality", "jacobian_ratio", "label", "element_type"):
    if key in m.cell_data:
        print("sum:" + key, sum(float(np.sum(d)) for d in m.cell_data[key]))
for name, cells in sorted(m.cell_sets.items()):
    print("cell_set:" + name, sum(len(c) for c in cells))
for name, points in sorted(m.point_sets.items()):
    print("point_set:" + name, len(points))
for name in sorted(m.field_data):
    print("field:" + name, *m.field_data[name])
print("point8", *(repr(float(x)) for x in m.points[8]))
)";
  const auto [status, output] = run("/usr/bin/python3 " + script + " " + path);
  EXPECT_EQ(status, 0) << output;
  std::map<std::string, std::string> summary;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    const auto space = line.find(' ');
    summary[line.substr(0, space)] = space == std::string::npos ? "" : line.substr(space + 1);
  }
  return summary;
}

// The four cells of all_four_types, positive and adding up to 1.75 mm³. Abaqus has the pyramid
// as a hexahedron.
void expect_four_cells(const std::map<std::string, std::string>& summary, bool pyramid_as_hex) {
  ASSERT_TRUE(summary.count("points")) << "meshio could not read the file";
  EXPECT_EQ(summary.at("points"), "12");
  EXPECT_EQ(summary.at("hexahedron"), pyramid_as_hex ? "2" : "1");
  EXPECT_EQ(summary.at("pyramid"), pyramid_as_hex ? "0" : "1");
  EXPECT_EQ(summary.at("wedge"), "1");
  EXPECT_EQ(summary.at("tetra"), "1");
  for (std::string kind : {"hexahedron", "wedge", "tetra"})
    EXPECT_GT(std::stod(summary.at("min_volume:" + kind)), 0) << kind;
  if (!pyramid_as_hex) {
    EXPECT_GT(std::stod(summary.at("min_volume:pyramid")), 0);
  }
  EXPECT_NEAR(std::stod(summary.at("total_volume")), 1.75, 1e-12);
}

struct Written {
  std::filesystem::path dir;
  std::string path;
  MixedMesh mesh;
  MixedQuality quality;
};

Written write_all_four(VolumeFormat format, std::string_view test) {
  Written w{testing::scratch_dir(test), "", all_four_types(), {}};
  w.quality = measure_mixed_mesh(w.mesh);
  // Distinct values, so a misplaced one shows.
  w.quality.quality = {0.9, 0.8, 0.7, 0.6};
  w.path = (w.dir / ("mixed." + std::string(volume_format_name(format)))).string();
  const auto status = write_mixed_mesh(w.mesh, w.quality, w.path, format, names());
  EXPECT_THAT(status, testing::IsOk());
  return w;
}

TEST(MixedMeshWrite, VtuReadsBackWithCellTypesAndQuality) {
  const Written w = write_all_four(VolumeFormat::kVtu, "mixed-vtu");
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(w.path.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfPoints(), 12);
  ASSERT_EQ(grid->GetNumberOfCells(), 4);
  const int types[4] = {VTK_HEXAHEDRON, VTK_PYRAMID, VTK_WEDGE, VTK_TETRA};
  auto* element_type = vtkIntArray::SafeDownCast(grid->GetCellData()->GetArray("element_type"));
  auto* label = vtkIntArray::SafeDownCast(grid->GetCellData()->GetArray("label"));
  vtkDataArray* jacobian_ratio = grid->GetCellData()->GetArray("jacobian_ratio");
  vtkDataArray* quality = grid->GetCellData()->GetArray("quality");
  ASSERT_NE(element_type, nullptr);
  ASSERT_NE(label, nullptr);
  ASSERT_NE(jacobian_ratio, nullptr);
  ASSERT_NE(quality, nullptr);
  for (vtkIdType c = 0; c < 4; ++c) {
    EXPECT_EQ(grid->GetCellType(c), types[c]);
    EXPECT_EQ(element_type->GetValue(c), types[c]);
    EXPECT_EQ(label->GetValue(c), w.mesh.labels[size_t(c)]);
    EXPECT_EQ(jacobian_ratio->GetTuple1(c), w.quality.jacobian_ratio[size_t(c)]);
    EXPECT_EQ(quality->GetTuple1(c), w.quality.quality[size_t(c)]);
    vtkIdType n;
    const vtkIdType* ids;
    grid->GetCellPoints(c, n, ids);
    ASSERT_EQ(n, node_count(w.mesh.types[size_t(c)]));
    for (vtkIdType k = 0; k < n; ++k) EXPECT_EQ(ids[k], vtkIdType(w.mesh.cells[size_t(c)][k]));
  }

  const auto summary = meshio_summary(w.dir, w.path);
  expect_four_cells(summary, false);
  EXPECT_EQ(summary.at("field:label_1_body"), "1");
  EXPECT_EQ(summary.at("field:label_2_side_wedge"), "2");
  EXPECT_EQ(summary.at("field:label_3_tip"), "3");
  EXPECT_EQ(summary.at("field:SPACE=LPS"), "1");
  EXPECT_EQ(std::stod(summary.at("sum:element_type")), 12 + 14 + 13 + 10);
}

TEST(MixedMeshWrite, MshPassesGmshCheckWithPhysicalNames) {
  const Written w = write_all_four(VolumeFormat::kMsh, "mixed-msh");
  const std::string text = read_text(w.path);
  EXPECT_NE(text.find("$PhysicalNames\n3\n3 1 \"label_1_body\"\n3 2 \"label_2_side_wedge\"\n"
                      "3 3 \"label_3_tip\"\n"),
            std::string::npos);
  // The wedge 1,9,5,2,10,6 (0-based) goes out as Gmsh's prism 2,6,10,3,7,11 (1-based).
  EXPECT_NE(text.find("\n3 6 2 2 2 2 6 10 3 7 11\n"), std::string::npos) << text;

  const auto summary = meshio_summary(w.dir, w.path);
  expect_four_cells(summary, false);
  EXPECT_EQ(summary.at("hexahedron:gmsh:physical"), "1");
  EXPECT_EQ(summary.at("wedge:gmsh:physical"), "2");
  EXPECT_EQ(summary.at("tetra:gmsh:geometrical"), "3");
  EXPECT_EQ(summary.at("field:label_2_side_wedge"), "2 3");

  // Gmsh's coherence check warns about negative volumes, duplicate nodes and elements.
  const auto [status, output] = run("gmsh -check " + w.path);
  EXPECT_EQ(status, 0) << output;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.find("Warning"), std::string::npos) << line;
    EXPECT_EQ(line.find("Error"), std::string::npos) << line;
  }
  EXPECT_NE(output.find(": 12 nodes"), std::string::npos) << output;
  EXPECT_NE(output.find(": 4 elements"), std::string::npos) << output;

  // No element data: meshio cannot read it over several cell types.
  EXPECT_EQ(text.find("$ElementData"), std::string::npos);
}

TEST(MixedMeshWrite, MeditHasCellsAndLabelBoundaries) {
  const Written w = write_all_four(VolumeFormat::kMedit, "mixed-medit");
  const std::string text = read_text(w.path);
  EXPECT_NE(text.find("# ref 2: label_2_side_wedge\n"), std::string::npos);
  EXPECT_NE(text.find("\nPrisms\n1\n2 6 10 3 7 11 2\n"), std::string::npos) << text;
  const auto summary = meshio_summary(w.dir, w.path);
  expect_four_cells(summary, false);
  // Label 1 (cube and pyramid): 5 quads, 4 triangles; label 2 (wedge): 3 quads, 2 triangles;
  // label 3 (tetrahedron): 4 triangles. Interfaces count once for each side.
  EXPECT_EQ(summary.at("triangle"), "10");
  EXPECT_EQ(summary.at("quad"), "8");
  EXPECT_EQ(summary.at("triangle:medit:ref"), "1 2 3");
  EXPECT_EQ(summary.at("quad:medit:ref"), "1 2");
  EXPECT_EQ(summary.at("pyramid:medit:ref"), "1");
  EXPECT_EQ(summary.at("tetra:medit:ref"), "3");
}

TEST(MixedMeshWrite, AbaqusHasSetsPerLabelAndCalculixAcceptsIt) {
  const Written w = write_all_four(VolumeFormat::kAbaqus, "mixed-inp");
  const std::string text = read_text(w.path);
  EXPECT_NE(text.find("\n** pyramids: C3D8 with the apex repeated"), std::string::npos);
  EXPECT_NE(text.find("\n*ELEMENT, TYPE=C3D6\n3, 2, 6, 10, 3, 7, 11\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n2, 5, 6, 7, 8, 9, 9, 9, 9\n"), std::string::npos) << text;
  const auto summary = meshio_summary(w.dir, w.path);
  expect_four_cells(summary, true);
  EXPECT_EQ(summary.at("cell_set:LABEL_1_BODY"), "2");
  EXPECT_EQ(summary.at("cell_set:LABEL_2_SIDE_WEDGE"), "1");
  EXPECT_EQ(summary.at("cell_set:LABEL_3_TIP"), "1");
  EXPECT_EQ(summary.at("point_set:LABEL_1_BODY_BOUNDARY"), "9");
  EXPECT_EQ(summary.at("point_set:LABEL_3_TIP_BOUNDARY"), "4");

  // CalculiX solves a small load case on it and says nothing about a Jacobian.
  std::ofstream(w.dir / "job.inp") << text << R"(*MATERIAL, NAME=SOFT
*ELASTIC
1000, 0.3
*DENSITY
1e-9
*SOLID SECTION, ELSET=LABEL_1_BODY, MATERIAL=SOFT
*SOLID SECTION, ELSET=LABEL_2_SIDE_WEDGE, MATERIAL=SOFT
*SOLID SECTION, ELSET=LABEL_3_TIP, MATERIAL=SOFT
*BOUNDARY
1, 1, 3
2, 1, 3
3, 1, 3
4, 1, 3
*STEP
*STATIC
*DLOAD
LABEL_1_BODY, GRAV, 9810, 0, 0, -1
*NODE PRINT, NSET=LABEL_1_BODY_BOUNDARY
U
*END STEP
)";
  const auto [status, output] = run("cd " + w.dir.string() + " && ccx -i job");
  EXPECT_EQ(status, 0) << output;
  EXPECT_EQ(output.find("*ERROR"), std::string::npos) << output;
  EXPECT_EQ(output.find("*WARNING"), std::string::npos) << output;
  EXPECT_EQ(output.find("acobian"), std::string::npos) << output;
  EXPECT_NE(output.find("Job finished"), std::string::npos) << output;
}

// Names and the RAS frame reach every format, and no element turns inside out.
TEST(MixedMeshWrite, RasFrameInEveryFormat) {
  const auto dir = testing::scratch_dir("mixed-ras");
  const MixedMesh mesh = all_four_types();
  const MixedQuality quality = measure_mixed_mesh(mesh);
  VolumeFileInfo info = names();
  info.frame = CoordinateFrame::kRas;
  for (VolumeFormat format :
       {VolumeFormat::kVtu, VolumeFormat::kMsh, VolumeFormat::kMedit, VolumeFormat::kAbaqus}) {
    SCOPED_TRACE(std::string(volume_format_name(format)));
    const auto path = (dir / ("ras." + std::string(volume_format_name(format)))).string();
    ASSERT_THAT(write_mixed_mesh(mesh, quality, path, format, info), testing::IsOk());
    const auto summary = meshio_summary(dir, path);
    expect_four_cells(summary, format == VolumeFormat::kAbaqus);
    EXPECT_EQ(summary.at("point8"), "-0.5 -0.5 1.5");  // (0.5, 0.5, 1.5) in LPS
    if (format == VolumeFormat::kMedit || format == VolumeFormat::kAbaqus) {
      EXPECT_NE(read_text(path).find("SPACE=RAS"), std::string::npos);
    }
  }
}

TEST(MixedMeshWrite, BadInputsAreErrorsNamingTheFile) {
  const auto dir = testing::scratch_dir("mixed-errors");
  const MixedMesh mesh = all_four_types();
  const MixedQuality quality = measure_mixed_mesh(mesh);

  const std::string node = (dir / "x.node").string();
  const auto tetgen = write_mixed_mesh(mesh, quality, node, VolumeFormat::kTetgen);
  EXPECT_THAT(tetgen, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(tetgen.message()).find("tetrahedra only"), std::string::npos) << tetgen;
  EXPECT_FALSE(std::filesystem::exists(node));
  const std::string xdmf = (dir / "x.xdmf").string();
  const auto xdmf_status = write_mixed_mesh(mesh, quality, xdmf, VolumeFormat::kXdmf);
  EXPECT_THAT(xdmf_status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(xdmf_status.message()).find("tetrahedral meshes only"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(xdmf));

  const std::string msh = (dir / "x.msh").string();
  MixedQuality short_quality = quality;
  short_quality.quality.pop_back();
  const auto wrong_size = write_mixed_mesh(mesh, short_quality, msh, VolumeFormat::kMsh);
  EXPECT_THAT(wrong_size, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_EQ(std::string(wrong_size.message()).rfind(msh + ": 3 quality values", 0), 0u)
      << wrong_size;
  // No quality at all is fine.
  EXPECT_THAT(write_mixed_mesh(mesh, {}, msh, VolumeFormat::kMsh), testing::IsOk());

  MixedMesh unlabelled = mesh;
  unlabelled.labels[2] = 0;
  for (VolumeFormat format : {VolumeFormat::kMsh, VolumeFormat::kAbaqus}) {
    const auto status = write_mixed_mesh(unlabelled, {}, msh, format);
    EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << status;
    EXPECT_NE(std::string(status.message()).find("label 0"), std::string::npos) << status;
  }
  EXPECT_THAT(write_mixed_mesh(unlabelled, {}, (dir / "x.vtu").string(), VolumeFormat::kVtu),
              testing::IsOk());

  MixedMesh broken = mesh;
  broken.cells[0][3] = 99;
  EXPECT_EQ(write_mixed_mesh(broken, {}, msh, VolumeFormat::kMedit).code(),
            absl::StatusCode::kInvalidArgument);

  for (VolumeFormat format :
       {VolumeFormat::kVtu, VolumeFormat::kMsh, VolumeFormat::kMedit, VolumeFormat::kAbaqus}) {
    const std::string path = "/nonexistent/dir/x." + std::string(volume_format_name(format));
    const auto status = write_mixed_mesh(mesh, quality, path, format);
    EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInternal)) << status;
    EXPECT_NE(std::string(status.message()).find("/nonexistent/dir/x."), std::string::npos);
  }
}

}  // namespace
}  // namespace labelmesh::mixed_mesh
