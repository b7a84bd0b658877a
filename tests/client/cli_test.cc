// SPDX-License-Identifier: AGPL-3.0-or-later
// The labelmesh executable: exit codes, files and the report, end to end.
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <sstream>

#include "labelmesh/v1/report.pb.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

struct CliRun {
  int exit_code;
  std::string output;  // stdout and stderr
};

CliRun run_cli(const std::string& arguments) {
  const std::string command = std::string(LABELMESH_CLI) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(Cli, MeshWritesSurfacesAndReport) {
  const auto dir = testing::scratch_dir("cli-mesh");
  ASSERT_EQ(run_cli("phantom nested-spheres --out " + (dir / "nested.nrrd").string()).exit_code, 0);
  const CliRun run =
      run_cli("mesh " + (dir / "nested.nrrd").string() + " --out " + (dir / "out").string() +
              " --labels 1,3 --surface mc --formats stl,ply,off");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"surface-label1.stl", "surface-label1.ply", "surface-label3.off"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / name)) << name;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "surface-label2.stl"));
  v1::Report report;
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(slurp(dir / "out" / "report.json"), &report)
          .ok());
  EXPECT_EQ(report.input().convention(), "LPS");
  EXPECT_EQ(report.input().format(), "nrrd");
  // The phantom is drawn on every voxel plane: none repeats.
  ASSERT_EQ(report.input().repeated_planes_size(), 3);
  ASSERT_EQ(report.input().drawn_spacing_size(), 3);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(report.input().repeated_planes(axis), 1u);
    EXPECT_EQ(report.input().drawn_spacing(axis), report.input().spacing(axis));
  }
  ASSERT_EQ(report.input().labels_size(), 3);
  ASSERT_EQ(report.surfaces_size(), 2);
  EXPECT_EQ(report.surfaces(0).label(), 1);
  EXPECT_EQ(report.surfaces(1).label(), 3);
  for (const auto& s : report.surfaces()) {
    EXPECT_EQ(s.stage(), "marching_cubes");
    EXPECT_TRUE(s.closed());
    EXPECT_TRUE(s.manifold());
    EXPECT_GT(s.min_angle_deg(), 0);
    EXPECT_LT(s.max_angle_deg(), 180);
    EXPECT_EQ(s.files_size(), 3);
  }
  const double ball = 4.0 / 3.0 * std::numbers::pi * 6 * 6 * 6;
  EXPECT_NEAR(report.surfaces(0).volume_mm3() / ball, 1.0, 0.03);
  std::vector<std::string> stages;
  for (const auto& stage : report.stages()) stages.push_back(stage.name());
  EXPECT_EQ(stages,
            (std::vector<std::string>{"read", "drawn_grid", "label_statistics", "marching_cubes",
                                      "surface_statistics", "write", "report_pictures"}));
  // The raw JSON keeps the proto field names.
  const std::string json = slurp(dir / "out" / "report.json");
  EXPECT_NE(json.find("\"min_angle_deg\""), std::string::npos);
  EXPECT_NE(json.find("\"triangles_below_30_deg\""), std::string::npos);
}

// Names from an ITK-SNAP label file reach the file names and the report.
TEST(Cli, LabelNamesNameTheSurfaceFiles) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("cli-label-names");
  const std::string out = (dir / "out").string();
  const CliRun run = run_cli("mesh " + testing::shared_data("MRIcrop-seg_converted.nii.gz") +
                             " --out " + out + " --labels 4 --surface repaired --label-names " +
                             testing::shared_data("MRIcrop-seg.label"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "surface-label4-hippo-r.stl"));
  std::ifstream report(dir / "out" / "report.json");
  const std::string text((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(text.find("\"name\": \"hippo-R\""), std::string::npos);
  // The summary table names the label.
  EXPECT_NE(run.output.find("      4  hippo-R "), std::string::npos) << run.output;
  EXPECT_NE(run_cli("mesh x.nii.gz --out d --label-names /no/such.label").exit_code, 0);
}

// RAS coordinates are LPS with x and y negated, in every surface file, and the
// files say so.
TEST(Cli, RasCoordinatesNegateXAndY) {
  const auto dir = testing::scratch_dir("cli-ras");
  const std::string input = (dir / "torus.mha").string();
  ASSERT_EQ(run_cli("phantom torus --out " + input).exit_code, 0);
  for (const char* frame : {"lps", "ras"}) {
    const CliRun run = run_cli("mesh " + input + " --out " + (dir / frame).string() +
                               " --surface repaired --formats obj,vtm --coordinates " + frame);
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  const std::string lps = slurp(dir / "lps" / "surface-label1.obj");
  const std::string ras = slurp(dir / "ras" / "surface-label1.obj");
  EXPECT_EQ(lps.rfind("# SPACE=LPS\n", 0), 0u);
  EXPECT_EQ(ras.rfind("# SPACE=RAS\n", 0), 0u);
  auto first_vertex = [](const std::string& obj) {
    std::istringstream in(obj.substr(obj.find("\nv ") + 3));
    std::array<double, 3> p{};
    in >> p[0] >> p[1] >> p[2];
    return p;
  };
  const auto a = first_vertex(lps), b = first_vertex(ras);
  EXPECT_EQ(b[0], -a[0]);
  EXPECT_EQ(b[1], -a[1]);
  EXPECT_EQ(b[2], a[2]);
  EXPECT_TRUE(std::filesystem::exists(dir / "ras" / "surfaces.vtm"));
  EXPECT_NE(slurp(dir / "ras" / "report.json").find("\"files_frame\": \"RAS\""), std::string::npos);
  EXPECT_EQ(
      run_cli("mesh " + input + " --out " + (dir / "x").string() + " --coordinates xyz").exit_code,
      2);
}

TEST(Cli, VersionIsTheProjects) {
  const CliRun run = run_cli("--version");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.output.find("labelmesh " LABELMESH_VERSION), std::string::npos) << run.output;
}

TEST(Cli, JsonReportOnStdout) {
  const auto dir = testing::scratch_dir("cli-json");
  ASSERT_EQ(run_cli("phantom torus --out " + (dir / "t.mha").string()).exit_code, 0);
  // Poisson on every label, however thin.
  const CliRun run = run_cli("mesh " + (dir / "t.mha").string() + " --out " + (dir / "o").string() +
                             " --surface poisson --poisson-min-thickness 0 --json 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0);
  v1::Report report;
  ASSERT_THAT(google::protobuf::util::JsonStringToMessage(run.output, &report), testing::IsOk())
      << run.output;
  // With Poisson, the report lists the Marching Cubes, repaired and
  // Poisson stages (Table 2's columns); only the last is the output.
  ASSERT_EQ(report.surfaces_size(), 3);
  EXPECT_EQ(report.surfaces(0).stage(), "marching_cubes");
  EXPECT_EQ(report.surfaces(1).stage(), "repaired");
  const auto& poisson = report.surfaces(2);
  EXPECT_EQ(poisson.stage(), "poisson");
  EXPECT_TRUE(poisson.output());
  EXPECT_FALSE(report.surfaces(0).output());
  EXPECT_EQ(poisson.euler_characteristic(), 0);
  EXPECT_GE(poisson.min_angle_deg(), 29.99);
  ASSERT_TRUE(poisson.has_self_intersections());
  EXPECT_EQ(poisson.self_intersections(), 0u);
  ASSERT_TRUE(poisson.has_hausdorff_mm());
  EXPECT_LT(poisson.hausdorff_mm(), 1.5);
  EXPECT_FALSE(report.surfaces(0).has_hausdorff_mm());
  EXPECT_EQ(poisson.components_kept(), 1u);
  EXPECT_GT(poisson.poisson().used_points(), 100u);
  // The torus phantom has 1 mm voxels and is far below the point budget: the
  // 1-voxel grid.
  EXPECT_DOUBLE_EQ(poisson.poisson().point_cell_mm(), 1.0);
  EXPECT_EQ(report.options().surface(), v1::SURFACE_METHOD_POISSON);
  EXPECT_EQ(report.options().min_angle_deg(), 30);
  EXPECT_TRUE(std::filesystem::exists(dir / "o" / "surface-label1.stl"));
}

TEST(Cli, TetrahedralMeshFilesForSolvers) {
  const auto dir = testing::scratch_dir("cli-volume");
  ASSERT_EQ(run_cli("phantom sphere --out " + (dir / "s.nii.gz").string()).exit_code, 0);
  const std::string mesh =
      "mesh " + (dir / "s.nii.gz").string() + " --out " + (dir / "o").string() + " --json";
  const CliRun run = run_cli(mesh + " --volume tet --formats stl,vtu,msh,inp,mesh 2>/dev/null");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  v1::Report report;
  ASSERT_THAT(google::protobuf::util::JsonStringToMessage(run.output, &report), testing::IsOk())
      << run.output;
  ASSERT_TRUE(report.has_volume());
  EXPECT_EQ(report.volume().mesher(), "tetgen");
  EXPECT_GT(report.volume().tetrahedra(), 500u);
  EXPECT_EQ(report.volume().categories().invalid(), 0u);
  EXPECT_EQ(report.volume().categories().good() + report.volume().categories().questionable() +
                report.volume().categories().very_bad(),
            report.volume().tetrahedra());
  EXPECT_GT(report.volume().tetra_quality_min(), 0);
  EXPECT_FALSE(report.volume().conforming());
  EXPECT_EQ(report.options().volume(), v1::VOLUME_METHOD_TETGEN);
  ASSERT_EQ(report.volume().files_size(), 4);
  for (const char* name : {"volume.vtu", "volume.msh", "volume.inp", "volume.mesh"})
    EXPECT_TRUE(std::filesystem::exists(dir / "o" / name)) << name;
  // A volume format needs a volume method; TetGen options are checked first.
  const CliRun no_volume = run_cli(mesh + " --formats vtu");
  EXPECT_EQ(no_volume.exit_code, 2);
  EXPECT_NE(no_volume.output.find("volume"), std::string::npos) << no_volume.output;
  const CliRun ratio = run_cli(mesh + " --volume tet --tet-radius-edge 0.5");
  EXPECT_EQ(ratio.exit_code, 2);
  EXPECT_NE(ratio.output.find("tet_radius_edge"), std::string::npos) << ratio.output;
}

TEST(Cli, BadPoissonOptionsAreUsageErrors) {
  const auto dir = testing::scratch_dir("cli-poisson-options");
  ASSERT_EQ(run_cli("phantom sphere --out " + (dir / "s.nii").string()).exit_code, 0);
  const std::string mesh =
      "mesh " + (dir / "s.nii").string() + " --out " + (dir / "o").string() + " --surface poisson";
  const CliRun angle = run_cli(mesh + " --min-angle 35");
  EXPECT_EQ(angle.exit_code, 2);
  EXPECT_NE(angle.output.find("min_angle_deg"), std::string::npos) << angle.output;
  EXPECT_EQ(run_cli(mesh + " --max-edge 0").exit_code, 2);
  EXPECT_EQ(run_cli(mesh + " --max-distance -1").exit_code, 2);
  EXPECT_EQ(run_cli(mesh + " --point-reduction octree").exit_code, 2);
  EXPECT_EQ(run_cli(mesh + " --point-reduction hierarchy --point-cluster-size 0").exit_code, 2);
  EXPECT_EQ(run_cli(mesh + " --point-cluster-size 65").exit_code, 2);
  // A refusal by the job-options check names the field.
  auto expect_refusal_naming = [&](const std::string& flags, const std::string& field) {
    const CliRun run = run_cli(mesh + " " + flags);
    EXPECT_EQ(run.exit_code, 2) << flags;
    EXPECT_NE(run.output.find(field), std::string::npos) << run.output;
  };
  expect_refusal_naming("--max-points 500", "max_points");
  EXPECT_EQ(run_cli(mesh + " --max-points -1").exit_code, 2);
  expect_refusal_naming("--split-points 999", "split_points");
  EXPECT_EQ(run_cli(mesh + " --min-component-voxels -1").exit_code, 2);
  expect_refusal_naming("--smoothing-pass-band 2.5", "smoothing_pass_band");
  EXPECT_EQ(run_cli(mesh + " --smoothing-iterations -3").exit_code, 2);
  // Every component under the size threshold: nothing left to mesh.
  const CliRun nothing = run_cli(mesh + " --min-component-voxels 100000");
  EXPECT_EQ(nothing.exit_code, 4);
  EXPECT_NE(nothing.output.find("min-component-voxels"), std::string::npos) << nothing.output;
}

TEST(Cli, InfoJsonOnRealData) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const CliRun run = run_cli("info --json " + testing::shared_data("liver.inr.gz"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  v1::InputSummary summary;
  ASSERT_THAT(google::protobuf::util::JsonStringToMessage(run.output, &summary), testing::IsOk())
      << run.output;
  EXPECT_EQ(summary.dims(0), 438u);
  ASSERT_EQ(summary.labels_size(), 4);
  EXPECT_EQ(summary.labels(3).label(), 255);
  EXPECT_EQ(summary.labels(3).voxels(), 6322002u);
  EXPECT_NEAR(summary.labels(3).volume_mm3(), 6322002 * 0.617188 * 0.617188 * 0.666667, 1.0);
}

TEST(Cli, ExitCodes) {
  const auto dir = testing::scratch_dir("cli-codes");
  EXPECT_EQ(run_cli("").exit_code, 2);
  EXPECT_EQ(run_cli("mesh x.nii").exit_code, 2);  // --out missing
  EXPECT_EQ(run_cli("mesh x.nii --out d --formats xyz").exit_code, 2);
  EXPECT_EQ(run_cli("phantom cube --out x.nii").exit_code, 2);

  const CliRun missing = run_cli("info " + (dir / "missing.nii").string());
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.output.find("missing.nii"), std::string::npos);

  testing::write_file(dir / "broken.nii", testing::Nifti1Bytes(4, 4, 4).bytes().substr(0, 200));
  const CliRun broken =
      run_cli("mesh " + (dir / "broken.nii").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(broken.exit_code, 3);
  EXPECT_NE(broken.output.find("broken.nii: header"), std::string::npos) << broken.output;

  testing::write_file(dir / "empty.nii", testing::Nifti1Bytes(4, 4, 4).bytes());
  const CliRun empty =
      run_cli("mesh " + (dir / "empty.nii").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(empty.exit_code, 4);
  EXPECT_NE(empty.output.find("only background"), std::string::npos) << empty.output;

  ASSERT_EQ(run_cli("phantom sphere --out " + (dir / "s.vti").string()).exit_code, 0);
  const CliRun absent =
      run_cli("mesh " + (dir / "s.vti").string() + " --labels 5 --out " + (dir / "o").string());
  EXPECT_EQ(absent.exit_code, 3);
  EXPECT_NE(absent.output.find("label 5"), std::string::npos) << absent.output;
}

TEST(Cli, HelpDocumentsExitCodes) {
  const CliRun run = run_cli("mesh --help");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.output.find("3 bad input"), std::string::npos) << run.output;
}

// --strict gives exit 4 on any warning, a volume mesh not delivered included:
// at 2 mm hexahedra every nested shell is left out.
TEST(Cli, StrictFailsWhenAVolumeMeshIsNotDelivered) {
  const auto dir = testing::scratch_dir("cli-strict-hex");
  const auto input = (dir / "nested.nii.gz").string();
  ASSERT_EQ(run_cli("phantom nested-spheres --out " + input).exit_code, 0);
  const std::string mesh = "mesh " + input + " --volume hex --hex-size 2 --formats vtu";
  const CliRun lenient = run_cli(mesh + " --out " + (dir / "lenient").string() + " 2>&1");
  EXPECT_EQ(lenient.exit_code, 0) << lenient.output;
  // Shell 2 touches ball 1 and shell 3: separate meshes, said on stderr.
  EXPECT_NE(lenient.output.find("2 pair(s) of labels touch"), std::string::npos) << lenient.output;
  EXPECT_NE(lenient.output.find("labels 1 and 2:"), std::string::npos) << lenient.output;
  const CliRun strict = run_cli(mesh + " --strict --out " + (dir / "strict").string() + " 2>&1");
  EXPECT_EQ(strict.exit_code, 4) << strict.output;
  EXPECT_NE(strict.output.find("no volume mesh"), std::string::npos) << strict.output;
}

// A DICOM SEG is known by its content: dcmqi's label.seg and a PACS file
// with no extension read like the .dcm they are.
TEST(Cli, DicomSegIsKnownByItsContentWhateverItsName) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto seg = testing::shared_data("dicom-seg/dcmqi-24x38x3-seg.dcm");
  if (!std::filesystem::exists(seg)) GTEST_SKIP() << "missing " << seg;
  const auto dir = testing::scratch_dir("cli-dicom-names");
  const CliRun named = run_cli("info " + seg);
  ASSERT_EQ(named.exit_code, 0) << named.output;
  ASSERT_NE(named.output.find("format       dicom-seg"), std::string::npos) << named.output;
  for (const char* name : {"label.seg", "1.2.840.113619.2.55"}) {
    const auto copy = dir / name;
    std::filesystem::copy_file(seg, copy, std::filesystem::copy_options::overwrite_existing);
    const CliRun info = run_cli("info " + copy.string());
    EXPECT_EQ(info.exit_code, 0) << info.output;
    // The same labels, line for line, below the file name.
    EXPECT_EQ(info.output.substr(info.output.find('\n')),
              named.output.substr(named.output.find('\n')))
        << name;
    const CliRun mesh =
        run_cli("mesh " + copy.string() + " --out " + (dir / name).string() + "-out");
    EXPECT_EQ(mesh.exit_code, 0) << mesh.output;
  }
  // Not DICOM and no known extension: bad input, saying both.
  std::ofstream(dir / "notes.seg") << std::string(200, 'x');
  const CliRun refused = run_cli("info " + (dir / "notes.seg").string());
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("not a DICOM file"), std::string::npos) << refused.output;
}

TEST(Cli, InfoCountsOverlappingSegmentsKeptApart) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto seg = testing::shared_data("dicom-seg/highdicom-seg_image_ct_binary_overlap.dcm");
  if (!std::filesystem::exists(seg)) GTEST_SKIP() << "missing " << seg;
  const CliRun refused = run_cli("info " + seg);
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("--overlapping separate"), std::string::npos) << refused.output;
  const CliRun separate = run_cli("info --overlapping separate " + seg);
  ASSERT_EQ(separate.exit_code, 0) << separate.output;
  EXPECT_NE(separate.output.find("layers       2"), std::string::npos) << separate.output;
  EXPECT_NE(separate.output.find("labels       2"), std::string::npos) << separate.output;
}

}  // namespace
}  // namespace labelmesh
