// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed meshes of phantom labels: hexahedra inside, and out to the surface
// either a layer of hexahedra or pyramids and tetrahedra; every element
// valid, the volume the surface's, every face shared node for node. The
// layer's patterns (the split into pyramids, the rank) on their own.
#include "core/mixed_mesh/mixed_mesher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <set>

#include "core/job/job_options.h"
#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/hex_layer.h"
#include "core/mixed_mesh/mixed_faces.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/quality/element_quality.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::mixed_mesh {
namespace {

namespace fs = std::filesystem;

// The delivered surface of `label` (the Poisson pipeline).
surface::TriangleMesh delivered_surface(const std::string& path, int32_t label) {
  MeshParams params;
  params.surface = SurfaceMethod::kPoisson;
  params.labels = {label};
  auto result = run_pipeline(path, params, {});
  EXPECT_THAT(result, testing::IsOk());
  for (auto& s : result->surfaces)
    if (s.is_output && s.label == label) return s.mesh;
  ADD_FAILURE() << "no output surface";
  return {};
}

surface::TriangleMesh phantom_surface(volume::PhantomShape shape, const std::string& name) {
  if (name == "liver") return delivered_surface(testing::shared_data("liver.inr.gz"), 255);
  const fs::path dir = testing::scratch_dir("mixed-" + name);
  const auto path = (dir / "phantom.nii.gz").string();
  EXPECT_THAT(volume::write_label_volume(volume::make_phantom(shape).volume, path),
              testing::IsOk());
  return delivered_surface(path, 1);
}

using Point = std::array<double, 3>;

struct Expect {
  volume::PhantomShape shape;
  const char* name;
  double cell_mm;
  // Least share of Table 1 "good" cells (quality above 0.2) with the
  // tetrahedral layer. The sphere's surface triangles (8 mm edges) are much
  // coarser than its 2 mm cubes, and TetGen keeps them, so tetrahedra
  // between the two are flatter there.
  double good_share;
  // Whether the label is thick enough for octants of four cubes inside.
  bool octants_fit;
};

class MixedMesher : public ::testing::TestWithParam<Expect> {};

// Both layers on the same surface: the tetrahedral one (valid by
// construction, the surface kept exactly) and the hexahedral one (the
// issue's floors, checked here again from the cells).
TEST_P(MixedMesher, BothLayersAreValidAndFillTheSurface) {
  const Expect expect = GetParam();
  if (std::string(expect.name) == "liver") LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto surface = phantom_surface(expect.shape, expect.name);
  ASSERT_FALSE(surface.triangles.empty());
  const double enclosed = surface::compute_surface_statistics(surface).volume_mm3;
  const auto oracle = SurfaceOracle::build(surface);
  ASSERT_THAT(oracle, testing::IsOk());

  MixedParams tet_layer;
  tet_layer.core.cell_mm = expect.cell_mm;
  tet_layer.hexahedral_layer = false;
  MixedFigures tet_figures;
  auto mesh = mesh_mixed(surface, 7, tet_layer, {}, tet_figures);
  ASSERT_THAT(mesh, testing::IsOk());
  {
    const MixedQuality q = measure_mixed_mesh(*mesh);
    EXPECT_GT(q.hexahedra, 0u);
    EXPECT_GT(q.pyramids, 0u);
    EXPECT_GT(q.tetrahedra, 0u);
    EXPECT_EQ(q.invalid, 0u);
    EXPECT_NEAR(q.volume_mm3, enclosed, 1e-6 * enclosed);
    EXPECT_GT(q.jacobian_ratio_min, 0.99);
    EXPECT_GT(*q.pyramid_aspect_ratio_min, 0.5);
    EXPECT_GT(q.tetra_summary.min, 0.02);
    EXPECT_GE(double(q.cell_summary.good), expect.good_share * double(mesh->size()));
    EXPECT_THAT(check_conformity(*mesh), testing::IsOk());
    std::printf("%s at %.1f mm, tetrahedral layer: %zu hexahedra, %zu pyramids, %zu tetrahedra\n",
                expect.name, expect.cell_mm, q.hexahedra, q.pyramids, q.tetrahedra);
  }

  MixedParams hex_layer;
  hex_layer.core.cell_mm = expect.cell_mm;
  MixedFigures figures;
  mesh = mesh_mixed(surface, 7, hex_layer, {}, figures);
  ASSERT_THAT(mesh, testing::IsOk());
  ASSERT_EQ(figures.layer_refused, "");
  const MixedQuality q = measure_mixed_mesh(*mesh);
  EXPECT_EQ(q.tetrahedra, 0u);
  EXPECT_EQ(q.invalid, 0u);
  EXPECT_GE(q.jacobian_ratio_min, 0.3);
  if (q.pyramid_aspect_ratio_min) {
    EXPECT_GE(*q.pyramid_aspect_ratio_min, 0.2);
  }
  EXPECT_GE(double(q.cell_summary.good), 0.99 * double(mesh->size()));
  EXPECT_GE(double(q.hexahedra), 0.7 * double(mesh->size()));
  EXPECT_NEAR(q.volume_mm3, enclosed, 0.01 * enclosed);
  EXPECT_LE(figures.layer.boundary_distance_max_mm, 0.05 * expect.cell_mm);
  const Conformity c = check_conformity(*mesh);
  EXPECT_TRUE(c.ok()) << c.nonconforming_faces << " nonconforming, " << c.duplicate_points
                      << " duplicates, " << c.open_boundary_edges << " open edges";
  // Every outer face of the mesh has its corners on the surface.
  size_t outer_corners = 0;
  for (const CellFace& face : label_boundary_faces(*mesh)) {
    for (int k = 0; k < face.size; ++k) {
      EXPECT_LE(std::abs(oracle->depth(mesh->points[face.points[k]])), 1e-6);
      ++outer_corners;
    }
  }
  EXPECT_GT(outer_corners, 0u);
  // The same with octants up to four cubes across inside: transitions in,
  // the layer and its floors unchanged, no more nodes (the torus's 6 mm tube
  // has no room for an octant).
  MixedParams octree = hex_layer;
  octree.octree.interior_mm = 4 * expect.cell_mm;
  MixedFigures octree_figures;
  auto coarse = mesh_mixed(surface, 7, octree, {}, octree_figures);
  ASSERT_THAT(coarse, testing::IsOk());
  ASSERT_EQ(octree_figures.layer_refused, "");
  const MixedQuality oq = measure_mixed_mesh(*coarse);
  EXPECT_EQ(oq.invalid, 0u);
  EXPECT_GE(oq.jacobian_ratio_min, 0.3);
  EXPECT_EQ(oq.cell_summary.good, int64_t(coarse->size()));
  EXPECT_NEAR(oq.volume_mm3, enclosed, 0.01 * enclosed);
  EXPECT_THAT(check_conformity(*coarse), testing::IsOk());
  EXPECT_EQ(octree_figures.octree.octants[1] > 0, expect.octants_fit);
  EXPECT_EQ(octree_figures.octree.transition_octants > 0, expect.octants_fit);
  EXPECT_LE(coarse->points.size(), mesh->points.size());
  std::printf(
      "%s with octants up to %.0f mm: %zu nodes (one size: %zu), %zu hexahedra, %zu "
      "pyramids, %zu tetrahedra, JR min %.3f\n",
      expect.name, 4 * expect.cell_mm, coarse->points.size(), mesh->points.size(), oq.hexahedra,
      oq.pyramids, oq.tetrahedra, oq.jacobian_ratio_min);
  std::printf(
      "%s at %.1f mm, hexahedral layer: %zu hexahedra (%zu in the layer), %zu pyramids "
      "(%llu split), JR min %.3f mean %.3f, scaled Jacobian min %.3f, good %.2f %%, volume "
      "%+.3f %%, boundary nodes within %.2g mm\n",
      expect.name, expect.cell_mm, q.hexahedra, size_t(figures.layer.layer_hexahedra), q.pyramids,
      (unsigned long long)figures.layer.split_hexahedra, q.jacobian_ratio_min,
      q.jacobian_ratio_mean, q.scaled_jacobian_min.value_or(0),
      100.0 * double(q.cell_summary.good) / double(mesh->size()),
      100 * (q.volume_mm3 / enclosed - 1), figures.layer.boundary_distance_max_mm);
}

INSTANTIATE_TEST_SUITE_P(
    Phantoms, MixedMesher,
    ::testing::Values(Expect{volume::PhantomShape::kSphere, "sphere", 2, 0.95, true},
                      Expect{volume::PhantomShape::kTorus, "torus", 1, 0.98, false},
                      Expect{volume::PhantomShape::kSphere, "liver", 2, 0.99, true}),
    [](const auto& info) { return std::string(info.param.name); });

// Hexahedra too distorted for the floor become six pyramids about one inner
// apex: each valid and above the floors, their volumes the hexahedron's,
// each face of the hexahedron a base exactly once. Random distortions of the
// unit cube (a fixed seed), every split checked.
TEST(HexLayerPattern, PoorHexahedraSplitIntoSixValidPyramids) {
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> jitter(-0.45, 0.45);
  HexLayerParams params;
  params.cell_mm = 1;
  size_t poor = 0, split = 0, inverted = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    MixedMesh mesh;
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (auto& p : mesh.points)
      for (double& x : p) x += jitter(random);
    mesh.add(CellType::kHexahedron, {0, 1, 2, 3, 4, 5, 6, 7}, 1);
    std::array<Point, 8> hex;
    std::copy(mesh.points.begin(), mesh.points.end(), hex.begin());
    // A hexahedron with an inverted corner may still be six valid pyramids:
    // their corners are not the hexahedron's.
    const double jr = quality::hexahedron_jacobian_ratio(hex);
    if (jr >= 0.3) continue;
    ++poor;
    inverted += jr <= 0;
    const auto apex = split_apex(hex, params);
    if (!apex) continue;
    ++split;
    mesh.points.push_back(*apex);
    const double hex_volume = cell_signed_volume(mesh, 0);
    MixedMesh pyramids;
    pyramids.points = mesh.points;
    for (const auto& p : pyramids_of(mesh.cells[0], 8)) pyramids.add(CellType::kPyramid, p, 1);
    ASSERT_THAT(check_mixed_mesh(pyramids), testing::IsOk());
    const MixedQuality q = measure_mixed_mesh(pyramids);
    EXPECT_EQ(q.pyramids, 6u);
    EXPECT_EQ(q.invalid, 0u);
    EXPECT_GE(q.jacobian_ratio_min, 0.3) << "trial " << trial;
    EXPECT_GE(*q.pyramid_aspect_ratio_min, 0.2) << "trial " << trial;
    EXPECT_NEAR(q.volume_mm3, hex_volume, 1e-12) << "trial " << trial;
    // The pyramids meet face to face; their outside is the hexahedron's.
    const Conformity c = check_conformity(pyramids);
    EXPECT_THAT(c, testing::IsOk());
    EXPECT_EQ(c.boundary_faces, 6u);
    EXPECT_EQ(c.interior_faces, 12u);
  }
  std::printf("%zu poor hexahedra (%zu inverted), %zu split into pyramids\n", poor, inverted,
              split);
  EXPECT_GT(inverted, 0u);
  EXPECT_GT(poor, 50u);
  EXPECT_GT(split, poor / 20);
}

// The layer's rank sees shear the Jacobian ratio misses: a parallelepiped
// has ratio 1 however sheared, its rank is twice the scaled Jacobian.
TEST(HexLayerPattern, RankFallsWithShear) {
  MixedMesh mesh;
  const double shift = std::tan(60 * M_PI / 180);  // 30° between the top's edge and the axis
  mesh.points = {{0, 0, 0},     {1, 0, 0},         {1, 1, 0},         {0, 1, 0},
                 {shift, 0, 1}, {1 + shift, 0, 1}, {1 + shift, 1, 1}, {shift, 1, 1}};
  mesh.add(CellType::kHexahedron, {0, 1, 2, 3, 4, 5, 6, 7}, 1);
  std::array<Point, 8> p;
  for (int k = 0; k < 8; ++k) p[k] = mesh.points[k];
  EXPECT_NEAR(quality::hexahedron_jacobian_ratio(p), 1, 1e-12);
  EXPECT_NEAR(quality::hexahedron_scaled_jacobian(p), 0.5, 1e-12);
  EXPECT_NEAR(layer_cell_rank(mesh, 0), 1, 1e-12);
  mesh.points[4][0] = mesh.points[5][0] = mesh.points[6][0] = mesh.points[7][0] = 0;
  mesh.points[5][0] = mesh.points[6][0] = 1;
  for (int k = 0; k < 8; ++k) p[k] = mesh.points[k];
  EXPECT_NEAR(layer_cell_rank(mesh, 0), 1, 1e-12);  // the unit cube
  mesh.points[4] = {3, 0, 1};
  mesh.points[5] = {4, 0, 1};
  mesh.points[6] = {4, 1, 1};
  mesh.points[7] = {3, 1, 1};
  for (int k = 0; k < 8; ++k) p[k] = mesh.points[k];
  EXPECT_NEAR(layer_cell_rank(mesh, 0), 2 * quality::hexahedron_scaled_jacobian(p), 1e-12);
  EXPECT_LT(layer_cell_rank(mesh, 0), 0.7);
}

// The pipeline's mixed stage on the nested spheres (labels 1 to 3): each
// label's cells conform, nothing is inverted, the cells hold the surfaces'
// volume, and the files say so. At 2 mm the shells are too thin for a
// hexahedral layer that keeps the volume, so every label gets the
// tetrahedral one, and the report says why.
TEST(MixedVolumeStage, NestedSpheresConformAndKeepTheirVolume) {
  const fs::path dir = testing::scratch_dir("mixed-stage");
  const auto path = (dir / "nested.nii.gz").string();
  ASSERT_TRUE(volume::write_label_volume(
                  volume::make_phantom(volume::PhantomShape::kNestedSpheres).volume, path)
                  .ok());
  MeshParams params;
  params.surface = SurfaceMethod::kPoisson;
  params.volume = VolumeMethod::kMixed;
  params.hex_size_mm = 2;
  params.volume_formats = {volume_mesh::VolumeFormat::kVtu, volume_mesh::VolumeFormat::kMsh,
                           volume_mesh::VolumeFormat::kMedit, volume_mesh::VolumeFormat::kAbaqus};
  auto result = run_pipeline(path, params, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_TRUE(result->mixed.has_value());
  ASSERT_THAT(write_results(*result, params, (dir / "out").string(), {}), testing::IsOk());
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
  ASSERT_EQ(v.tetrahedral_layer_labels_size(), 3);
  EXPECT_NE(v.tetrahedral_layer_labels(0).reason().find("below the surface's"), std::string::npos)
      << v.tetrahedral_layer_labels(0).reason();
  EXPECT_EQ(v.tetrahedral_layer_labels(1).reason(), "too thin for a single 2 mm cube");
  EXPECT_EQ(v.labels_left_out_size(), 0);
  ASSERT_EQ(v.files_size(), 4);
  for (const auto& file : v.files()) EXPECT_GT(fs::file_size(dir / "out" / file), 0u) << file;
}

// Hexahedra only: at 1.5 mm the innermost sphere gets them and the two
// shells are left out with their reasons, in the report and its warnings;
// at 2 mm every label is left out and no volume file is written.
TEST(MixedVolumeStage, HexahedraOnlyLeavesOutWhatCannotBeValid) {
  const fs::path dir = testing::scratch_dir("hex-stage");
  const auto path = (dir / "nested.nii.gz").string();
  ASSERT_TRUE(volume::write_label_volume(
                  volume::make_phantom(volume::PhantomShape::kNestedSpheres).volume, path)
                  .ok());
  v1::MeshOptions options;
  options.set_volume(v1::VOLUME_METHOD_HEX);
  options.set_hex_size_mm(1.5);
  options.add_formats("vtu");
  auto params = params_from_options(options);
  ASSERT_THAT(params, testing::IsOk());
  auto result = run_pipeline(path, *params, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_THAT(write_results(*result, *params, (dir / "fine").string(), {}), testing::IsOk());
  v1::Report report = make_report(*result, *params);
  const auto& v = report.volume();
  EXPECT_EQ(v.mesher(), "hex_grid");
  EXPECT_GT(v.hexahedra(), 1000u);
  EXPECT_EQ(v.pyramids() + v.prisms() + v.tetrahedra(), 0u);
  EXPECT_EQ(v.inverted(), 0u);
  EXPECT_GE(v.jacobian_ratio_min(), 0.3);
  EXPECT_GT(v.scaled_jacobian_min(), 0);
  EXPECT_LT(std::abs(v.volume_change()), 0.01);
  EXPECT_EQ(v.conformity_check().nonconforming_faces(), 0u);
  EXPECT_EQ(v.conformity_check().open_boundary_edges(), 0u);
  std::set<int32_t> labels(result->mixed->mesh.labels.begin(), result->mixed->mesh.labels.end());
  EXPECT_EQ(labels, (std::set<int32_t>{3}));
  ASSERT_EQ(v.labels_left_out_size(), 2);
  EXPECT_EQ(v.labels_left_out(0).label(), 1);
  EXPECT_EQ(v.labels_left_out(1).label(), 2);
  size_t volume_warnings = 0;
  for (const auto& w : report.warnings())
    volume_warnings += w.reason().rfind("no volume mesh: ", 0) == 0;
  EXPECT_EQ(volume_warnings, 2u);
  EXPECT_TRUE(fs::exists(dir / "fine" / "volume.vtu"));

  params->hex_size_mm = 2;
  result = run_pipeline(path, *params, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_THAT(write_results(*result, *params, (dir / "coarse").string(), {}), testing::IsOk());
  report = make_report(*result, *params);
  EXPECT_EQ(report.volume().labels_left_out_size(), 3);
  EXPECT_EQ(report.volume().hexahedra(), 0u);
  EXPECT_EQ(report.volume().files_size(), 0);
  EXPECT_FALSE(fs::exists(dir / "coarse" / "volume.vtu"));

  // --strict: a volume mesh not delivered fails the run like a surface does.
  params->guard.strict = true;
  result = run_pipeline(path, *params, {});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result, testing::StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_NE(std::string(result.status().message()).find("strict: 3 label(s)"), std::string::npos)
      << result.status();
  EXPECT_NE(std::string(result.status().message()).find("no volume mesh"), std::string::npos);
}

TEST(MixedVolumeStage, TetGenNodeFilesAreRefusedForMixedMeshes) {
  v1::MeshOptions options;
  options.set_volume(v1::VOLUME_METHOD_MIXED);
  options.add_formats("node");
  const auto params = params_from_options(options);
  ASSERT_FALSE(params.ok());
  EXPECT_THAT(params, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(std::string(params.status().message()).find("tetrahedra only"), std::string::npos);
  options.clear_formats();
  options.set_hex_size_mm(0.01);
  EXPECT_FALSE(params_from_options(options).ok());
  // An interior size must leave room for one coarser level.
  options.set_hex_size_mm(2);
  options.set_hex_interior_size_mm(3);
  auto refused = params_from_options(options);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(std::string(refused.status().message()).find("less than twice hex_size_mm"),
            std::string::npos);
  options.set_hex_interior_size_mm(8);
  auto taken = params_from_options(options);
  ASSERT_THAT(taken, testing::IsOk());
  EXPECT_EQ(taken->hex_interior_size_mm, 8);
  EXPECT_EQ(make_options(*taken).hex_interior_size_mm(), 8);
}

}  // namespace
}  // namespace labelmesh::mixed_mesh
