// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed meshes of phantom labels: hexahedra inside, pyramids on the core's
// boundary, tetrahedra out to the surface; every element valid, the volume
// the surface's, the core's boundary shared node for node.
#include "core/mixed_mesh/mixed_mesher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "core/pipeline/job_options.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/quality/element_quality.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "support/test_files.h"

namespace labelmesh::mixed_mesh {
namespace {

namespace fs = std::filesystem;

// The delivered surface of `label` (default Poisson pipeline).
surface::TriangleMesh delivered_surface(const std::string& path, int32_t label) {
  MeshParams params;
  params.labels = {label};
  auto result = run_pipeline(path, params, {});
  EXPECT_TRUE(result.ok()) << result.status();
  for (auto& s : result->surfaces)
    if (s.is_output && s.label == label) return s.mesh;
  ADD_FAILURE() << "no output surface";
  return {};
}

surface::TriangleMesh phantom_surface(volume::PhantomShape shape, const std::string& name) {
  if (name == "liver") return delivered_surface(testing::shared_data("liver.inr.gz"), 255);
  const fs::path dir = testing::scratch_dir("mixed-" + name);
  const auto path = (dir / "phantom.nii.gz").string();
  EXPECT_TRUE(volume::write_label_volume(volume::make_phantom(shape).volume, path).ok());
  return delivered_surface(path, 1);
}

template <size_t N>
std::array<quality::Point, N> corners(const MixedMesh& mesh, size_t c) {
  std::array<quality::Point, N> p;
  for (size_t k = 0; k < N; ++k) {
    p[k] = mesh.points[mesh.cells[c][k]];
  }
  return p;
}

// Signed volume of a cell: tetrahedra of a fan from its first node over its
// faces would need the face list; hexahedra and pyramids split at corner 0.
double cell_volume(const MixedMesh& mesh, size_t c) {
  switch (mesh.types[c]) {
    case CellType::kTetra:
      return quality::tetra_signed_volume(corners<4>(mesh, c));
    case CellType::kPyramid: {
      const auto p = corners<5>(mesh, c);
      return quality::tetra_signed_volume({p[0], p[1], p[2], p[4]}) +
             quality::tetra_signed_volume({p[0], p[2], p[3], p[4]});
    }
    case CellType::kHexahedron: {
      // Axis-aligned cubes here: edge 0-1 times 0-3 times 0-4.
      const auto p = corners<8>(mesh, c);
      return (p[1][0] - p[0][0]) * (p[3][1] - p[0][1]) * (p[4][2] - p[0][2]);
    }
    case CellType::kWedge:
      break;
  }
  return 0;
}

struct Expect {
  volume::PhantomShape shape;
  const char* name;
  double cell_mm;
  // Least share of Table 1 "good" cells (quality above 0.2). The sphere's
  // surface triangles (8 mm edges) are much coarser than its 2 mm cubes, and
  // TetGen keeps them, so tetrahedra between the two are flatter there.
  double good_share;
};

class MixedMesher : public ::testing::TestWithParam<Expect> {};

TEST_P(MixedMesher, ValidElementsFillTheSurfaceExactly) {
  const Expect expect = GetParam();
  const auto surface = phantom_surface(expect.shape, expect.name);
  ASSERT_FALSE(surface.triangles.empty());
  MixedParams params;
  params.core.cell_mm = expect.cell_mm;
  MixedFigures figures;
  auto mesh = mesh_mixed(surface, 7, params, {}, figures);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const size_t hexes = mesh->count(CellType::kHexahedron);
  const size_t pyramids = mesh->count(CellType::kPyramid);
  const size_t tets = mesh->count(CellType::kTetra);
  EXPECT_GT(hexes, 0u);
  EXPECT_GT(pyramids, 0u);
  EXPECT_GT(tets, 0u);
  EXPECT_EQ(hexes + pyramids + tets, mesh->size());

  double volume = 0, min_jr = 1, min_ar = 10, min_q = 1;
  size_t good = 0;
  for (size_t c = 0; c < mesh->size(); ++c) {
    const double v = cell_volume(*mesh, c);
    EXPECT_GT(v, 0) << "cell " << c;
    volume += v;
    if (mesh->types[c] == CellType::kHexahedron)
      min_jr = std::min(min_jr, quality::hexahedron_jacobian_ratio(corners<8>(*mesh, c)));
    if (mesh->types[c] == CellType::kPyramid) {
      min_jr = std::min(min_jr, quality::pyramid_jacobian_ratio(corners<5>(*mesh, c)));
      min_ar = std::min(min_ar, quality::pyramid_signed_aspect_ratio(corners<5>(*mesh, c)));
    }
    if (mesh->types[c] == CellType::kTetra) {
      const double q = quality::tetra_quality(corners<4>(*mesh, c));
      min_q = std::min(min_q, q);
      good += q > 0.2;
    } else {
      ++good;  // hexahedra and pyramids have a Jacobian ratio of 1 here
    }
  }
  const double enclosed = surface::compute_surface_statistics(surface).volume_mm3;
  EXPECT_NEAR(volume, enclosed, 1e-6 * enclosed);
  EXPECT_GT(min_jr, 0.99);
  EXPECT_GT(min_ar, 0.5);
  EXPECT_GT(min_q, 0.02);
  EXPECT_GE(double(good), expect.good_share * double(mesh->size()));
  std::printf(
      "%s at %.1f mm: %zu hexahedra, %zu pyramids, %zu tetrahedra (hexahedra %.0f %%), "
      "tetra Q min %.3f, pyramid AR min %.3f, good %.2f %%\n",
      expect.name, expect.cell_mm, hexes, pyramids, tets, 100.0 * hexes / mesh->size(), min_q,
      min_ar, 100.0 * double(good) / double(mesh->size()));
  std::printf(
      "  grid %llu cells, %llu depth queries, %llu trimmed; TetGen %zu points %zu triangles "
      "%zu Steiner; core %.3f s, TetGen %.3f s\n",
      (unsigned long long)figures.grid_cells, (unsigned long long)figures.depth_queries,
      (unsigned long long)figures.core_cells_removed, figures.tetgen.input_points,
      figures.tetgen.input_triangles, figures.tetgen.steiner_points, figures.core_seconds,
      figures.tetgen.seconds);
}

INSTANTIATE_TEST_SUITE_P(Phantoms, MixedMesher,
                         ::testing::Values(Expect{volume::PhantomShape::kSphere, "sphere", 2, 0.95},
                                           Expect{volume::PhantomShape::kTorus, "torus", 1.5, 0.99},
                                           Expect{volume::PhantomShape::kSphere, "liver", 2, 0.99}),
                         [](const auto& info) { return std::string(info.param.name); });

// The pipeline's mixed stage on the nested spheres (labels 1 to 3): each
// label's cells conform, nothing is inverted, the cells hold the surfaces'
// volume, and the files say so.
TEST(MixedVolumeStage, NestedSpheresConformAndKeepTheirVolume) {
  const fs::path dir = testing::scratch_dir("mixed-stage");
  const auto path = (dir / "nested.nii.gz").string();
  ASSERT_TRUE(volume::write_label_volume(
                  volume::make_phantom(volume::PhantomShape::kNestedSpheres).volume, path)
                  .ok());
  MeshParams params;
  params.volume = VolumeMethod::kMixed;
  params.hex_size_mm = 2;
  params.volume_formats = {volume_mesh::VolumeFormat::kVtu, volume_mesh::VolumeFormat::kMsh,
                           volume_mesh::VolumeFormat::kMedit, volume_mesh::VolumeFormat::kAbaqus};
  auto result = run_pipeline(path, params, {});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_TRUE(result->mixed.has_value());
  ASSERT_TRUE(write_results(*result, params, (dir / "out").string(), {}).ok());
  const v1::Report report = make_report(*result, params);
  ASSERT_TRUE(report.has_volume());
  const auto& v = report.volume();
  EXPECT_EQ(v.mesher(), "mixed_grid");
  EXPECT_EQ(v.hex_size_mm(), 2);
  EXPECT_GT(v.hexahedra(), 0u);
  EXPECT_GT(v.pyramids(), 0u);
  EXPECT_GT(v.tetrahedra(), 0u);
  EXPECT_EQ(v.inverted(), 0u);
  EXPECT_GT(v.jacobian_ratio_min(), 0.99);
  EXPECT_NEAR(v.volume_change(), 0, 1e-9);
  EXPECT_EQ(v.conformity_check().nonconforming_faces(), 0u);
  EXPECT_EQ(v.conformity_check().duplicate_points(), 0u);
  EXPECT_EQ(v.conformity_check().open_boundary_edges(), 0u);
  EXPECT_GT(v.conformity_check().interior_faces(), v.conformity_check().boundary_faces());
  std::set<int32_t> labels(result->mixed->mesh.labels.begin(), result->mixed->mesh.labels.end());
  EXPECT_EQ(labels, (std::set<int32_t>{1, 2, 3}));
  ASSERT_EQ(v.files_size(), 4);
  for (const auto& file : v.files()) EXPECT_GT(fs::file_size(dir / "out" / file), 0u) << file;
}

TEST(MixedVolumeStage, TetGenNodeFilesAreRefusedForMixedMeshes) {
  v1::MeshOptions options;
  options.set_volume(v1::VOLUME_METHOD_MIXED);
  options.add_formats("node");
  const auto params = params_from_options(options);
  ASSERT_FALSE(params.ok());
  EXPECT_EQ(params.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(params.status().message()).find("tetrahedra only"), std::string::npos);
  options.clear_formats();
  options.set_hex_size_mm(0.01);
  EXPECT_FALSE(params_from_options(options).ok());
}

}  // namespace
}  // namespace labelmesh::mixed_mesh
