// SPDX-License-Identifier: AGPL-3.0-or-later
// report.html: every label's figures, hostile names escaped, one chart per
// quality histogram, nothing fetched from the network, written beside
// report.json, and rendered by headless Chromium.
#include "core/pipeline/report_html.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <array>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "core/digest/sha256.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/surface_picture.h"
#include "core/pipeline/write_results.h"
#include "core/util/text.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

namespace fs = std::filesystem;

constexpr char kHostileName[] = "<script>alert(1)</script>";
constexpr char kEscapedHostileName[] = "&lt;script&gt;alert(1)&lt;/script&gt;";

void add_label(v1::InputSummary& input, int32_t label, uint64_t voxels, const std::string& name,
               std::initializer_list<uint32_t> colour) {
  auto* entry = input.add_labels();
  entry->set_label(label);
  entry->set_voxels(voxels);
  entry->set_volume_mm3(static_cast<double>(voxels) * 1.40625);
  entry->set_name(name);
  for (uint32_t c : colour) entry->add_colour_rgb(c);
}

v1::SurfaceSummary& add_surface(v1::Report& report, int32_t label, const std::string& stage,
                                uint32_t nodes, double min_angle, double max_angle) {
  auto* s = report.add_surfaces();
  s->set_label(label);
  s->set_stage(stage);
  s->set_nodes(nodes);
  s->set_triangles(2 * nodes - 4);
  s->set_min_angle_deg(min_angle);
  s->set_max_angle_deg(max_angle);
  return *s;
}

// Three labels: a named, coloured one within tolerance, one with a hostile
// name and a warning, and one whose stages failed.
v1::Report sample_report() {
  v1::Report report;
  report.set_labelmesh_version("0.1.0");
  auto& input = *report.mutable_input();
  input.set_format("nifti");
  input.set_voxel_type("uint8");
  input.set_convention("LPS");
  for (uint32_t d : {64u, 48u, 40u}) input.add_dims(d);
  for (double s : {0.75, 0.75, 2.5}) input.add_spacing(s);
  for (double s : {0.75, 0.75, 2.5}) input.add_drawn_spacing(s);
  for (double o : {-10.0, 20.0, 30.5}) input.add_origin(o);
  input.set_background_voxels(110000);
  add_label(input, 1, 12345, "liver", {221, 130, 101});
  add_label(input, 2, 678, kHostileName, {});
  add_label(input, 3, 90, "", {});

  add_surface(report, 1, "marching_cubes", 9999, 1.5, 170.0);
  auto& liver = add_surface(report, 1, "poisson", 4321, 31.4159, 112.5);
  liver.set_output(true);
  liver.set_volume_mm3(17012.34);
  liver.set_hausdorff_mm(1.23456);
  auto& hostile = add_surface(report, 2, "mask", 210, 20.5, 130.25);
  hostile.set_triangles_below_30_deg(37);
  hostile.set_output(true);
  hostile.set_volume_mm3(600.5);
  hostile.set_hausdorff_mm(2.5);
  add_surface(report, 3, "poisson", 0, 0, 0).set_error("no surface & no mask");

  auto* warning = report.add_warnings();
  warning->set_label(2);
  warning->set_reason("outside tolerance: mask surface, Hausdorff 2.50 mm");
  warning = report.add_warnings();
  warning->set_label(3);
  warning->set_reason("not delivered: no surface & no mask");
  return report;
}

v1::Report sample_report_with_volume() {
  v1::Report report = sample_report();
  auto* volume = report.mutable_volume();
  volume->set_mesher("tetgen");
  volume->set_nodes(1000);
  volume->set_tetrahedra(4567);
  volume->set_tetra_quality_min(0.0281234);
  volume->set_tetra_quality_mean(0.68);
  volume->set_min_dihedral_deg(7.25);
  volume->set_max_dihedral_deg(165.5);
  auto* categories = volume->mutable_categories();
  categories->set_invalid(0);
  categories->set_very_bad(2);
  categories->set_questionable(33);
  categories->set_good(4532);
  return report;
}

// A cube of half-size `half` mm around `centre`, as 12 triangles.
surface::TriangleMesh box_mesh(std::array<double, 3> centre, double half) {
  surface::TriangleMesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.points.push_back({centre[0] + (i & 1 ? half : -half), centre[1] + (i & 2 ? half : -half),
                           centre[2] + (i & 4 ? half : -half)});
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

size_t count(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

TEST(ReportHtml, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(html_escape(kHostileName), kEscapedHostileName);
  EXPECT_EQ(html_escape("a & b \"c\" 'd'"), "a &amp; b &quot;c&quot; &#39;d&#39;");
  EXPECT_EQ(html_escape("plain, caf\xC3\xA9"), "plain, caf\xC3\xA9");
}

TEST(ReportHtml, ShowsEveryLabelsOutputFigures) {
  const std::string html = report_html(sample_report());
  EXPECT_TRUE(absl::StartsWith(html, "<!DOCTYPE html>"));
  EXPECT_TRUE(absl::StrContains(html, "Coordinates are LPS millimetres"));
  for (const char* figure : {"nifti",
                             "uint8",
                             "64 &times; 48 &times; 40",
                             "0.7500 &times; 0.7500 &times; 2.5000",
                             "liver",
                             "rgb(221,130,101)",
                             ">12345<",
                             "17360.2",
                             ">poisson<",
                             ">4321<",
                             ">8638<",
                             ">31.42<",
                             ">112.50<",
                             ">17012.3<",
                             ">1.235<",
                             ">mask<",
                             ">20.50<",
                             ">37<",
                             ">130.25<",
                             ">2.500<",
                             "outside tolerance: mask surface, Hausdorff 2.50 mm",
                             "failed: no surface &amp; no mask"})
    EXPECT_TRUE(absl::StrContains(html, figure)) << figure;
  // The Marching Cubes stage is the reference, not the label's output.
  EXPECT_FALSE(absl::StrContains(html, ">9999<"));
}

// A mixed mesh's page shows its cells, Jacobian figures and the labels that
// fell back or were left out, their reasons escaped.
TEST(ReportHtml, ShowsAMixedMeshAndItsLabelsLeftOut) {
  v1::Report report = sample_report();
  auto* v = report.mutable_volume();
  v->Clear();
  v->set_mesher("mixed_grid");
  v->set_hex_size_mm(2);
  v->set_nodes(223487);
  v->set_hexahedra(208388);
  v->set_pyramids(12);
  v->set_jacobian_ratio_min(0.408);
  v->set_scaled_jacobian_min(0.204);
  v->set_volume_change(-0.00088);
  auto* refused = v->add_tetrahedral_layer_labels();
  refused->set_label(4);
  refused->set_reason("volume 3.9 % < surface's");
  auto* left_out = v->add_labels_left_out();
  left_out->set_label(5);
  left_out->set_reason(kHostileName);
  const std::string html = report_html(report);
  for (const char* figure : {"Volume mesh (mixed_grid)", ">223487<", ">208388<", ">12<", ">0.408<",
                             ">0.204<", ">-0.088<", "Labels with a tetrahedral outer layer",
                             "label 4: volume 3.9 % &lt; surface&#39;s", "Labels left out",
                             "Cells per quality category"})
    EXPECT_TRUE(absl::StrContains(html, figure)) << figure;
  EXPECT_TRUE(absl::StrContains(html, cat("label 5: ", kEscapedHostileName)));
  EXPECT_FALSE(absl::StrContains(absl::AsciiStrToLower(html), "<script"));
  EXPECT_FALSE(absl::StrContains(html, "Steiner points"));
}

// A conforming mesh is one tetrahedral mesh: its page shows tetrahedron
// quality, the interfaces and their check and each label's volume, never
// the hexahedral figures.
TEST(ReportHtml, ShowsAConformingMeshsInterfacesAndLabelVolumes) {
  v1::Report report = sample_report();
  auto* v = report.mutable_volume();
  v->set_mesher("conforming");
  v->set_nodes(52110);
  v->set_tetrahedra(280431);
  v->set_tetra_quality_min(0.1234);
  v->set_min_dihedral_deg(15.25);
  v->mutable_conformity_check()->set_nonconforming_faces(0);
  v->mutable_conformity_check()->set_duplicate_points(0);
  auto* c = v->mutable_conforming_figures();
  c->set_interfaces(7);
  c->set_interface_faces(18345);
  c->set_outer_faces(9021);
  c->set_interface_offset_max_mm(0.4321);
  c->set_volume_gap(2.5e-7);
  c->set_outside_regions(2);
  auto* label = c->add_labels();
  label->set_label(1);
  label->set_voxels(12345);
  label->set_voxel_volume_mm3(17360.16);
  label->set_mesh_volume_mm3(17298.73);
  label->set_tetrahedra(150321);
  label->set_volume_change(-0.003539);
  v->mutable_categories()->set_good(280000);
  const std::string html = report_html(report);
  for (const char* figure : {"Volume mesh (conforming: one mesh of every label)", ">52110<",
                             ">280431<", ">0.123<", ">15.25<", "Interface faces", ">18345<",
                             ">9021<", ">0.432<", ">0.0000<", ">2<", "Labels in the mesh",
                             ">17298.7<", ">150321<", ">-0.35<", "Tetrahedra per quality category"})
    EXPECT_TRUE(absl::StrContains(html, figure)) << figure;
  for (const char* hexahedral : {"Jacobian ratio", "Hexahedra", "Cube edge"})
    EXPECT_FALSE(absl::StrContains(html, hexahedral)) << hexahedral;
}

TEST(ReportHtml, NamesTheInputItsDigestAndWhenItWasMade) {
  v1::Report report = sample_report();
  report.mutable_input()->set_file_name(cat("scan ", kHostileName, ".nii.gz"));
  report.mutable_input()->set_sha256(std::string(64, 'a'));
  report.set_created_at("2026-01-31T12:00:00Z");
  const std::string html = report_html(report);
  EXPECT_TRUE(absl::StrContains(html, cat("<title>labelmesh report: scan ", kEscapedHostileName)));
  EXPECT_TRUE(absl::StrContains(html, cat("<td>scan ", kEscapedHostileName, ".nii.gz</td>")));
  EXPECT_TRUE(absl::StrContains(html, cat("<code>", std::string(64, 'a'), "</code>")));
  EXPECT_TRUE(absl::StrContains(html, "Made by labelmesh 0.1.0 on 2026-01-31T12:00:00Z."));
  EXPECT_FALSE(absl::StrContains(absl::AsciiStrToLower(html), "<script"));
}

TEST(ReportHtml, ShowsTheGridMeshedOnOnlyWhereItIsNotTheFiles) {
  v1::Report report = sample_report();
  EXPECT_FALSE(absl::StrContains(report_html(report), "Meshed on"));
  for (double spacing : {3.006, 3.006, 2.0}) report.mutable_input()->add_meshed_spacing(spacing);
  for (uint32_t dims : {167, 167, 20}) report.mutable_input()->add_meshed_dims(dims);
  const std::string html = report_html(report);
  EXPECT_TRUE(absl::StrContains(html, "<tr><th>Meshed on (mm)</th><td>3.0060"));
  EXPECT_TRUE(absl::StrContains(html, "167"));
}

TEST(ReportHtml, EscapesHostileNames) {
  const std::string html = report_html(sample_report());
  EXPECT_TRUE(absl::StrContains(html, kEscapedHostileName));
  EXPECT_FALSE(absl::StrContains(absl::AsciiStrToLower(html), "<script"));
}

// Two boxes, pictured as report.html shows them.
SurfacePictures box_pictures() {
  static const surface::TriangleMesh left = box_mesh({40, 0, 0}, 15);
  static const surface::TriangleMesh right = box_mesh({-40, 0, 0}, 10);
  return make_surface_pictures({{1, &left, {221, 130, 101}}, {2, &right, {55, 126, 184}}});
}

TEST(ReportHtml, NeedsNothingFromTheNetwork) {
  const SurfacePictures pictures = box_pictures();
  std::string html = report_html(sample_report_with_volume(), pictures);
  // The SVG namespace is a name, never fetched.
  const std::string svg_namespace = "http://www.w3.org/2000/svg";
  for (size_t at; (at = html.find(svg_namespace)) != std::string::npos;)
    html.erase(at, svg_namespace.size());
  // Pictures are inline PNG: one overview and one per label.
  const std::string inline_png = "<img src=\"data:image/png;base64,";
  EXPECT_EQ(count(html, inline_png), 1 + pictures.label_png.size());
  for (size_t at; (at = html.find(inline_png)) != std::string::npos;)
    html.erase(at, html.find('"', at + inline_png.size()) + 1 - at);
  for (const char* remote :
       {"http://", "https://", "//", "<link", "<img", "src=", "url(", "@import"})
    EXPECT_FALSE(absl::StrContains(html, remote)) << remote;
}

TEST(ReportHtml, OneChartPerHistogram) {
  // Surface angles only.
  const std::string surfaces = report_html(sample_report());
  EXPECT_EQ(count(surfaces, "<svg"), 1u);
  EXPECT_EQ(count(surfaces, "</svg>"), 1u);
  EXPECT_TRUE(absl::StrContains(surfaces, "31.42\xC2\xB0 to 112.50\xC2\xB0"));
  // With a volume mesh, its quality categories too.
  const std::string volume = report_html(sample_report_with_volume());
  EXPECT_EQ(count(volume, "<svg"), 2u);
  for (const char* figure : {">4567<", ">0.028<", ">0.680<", ">7.25<", ">165.50<", ">33<", ">4532<",
                             "invalid (Q", "questionable"})
    EXPECT_TRUE(absl::StrContains(volume, figure)) << figure;
}

std::string write_sphere(const fs::path& dir) {
  const auto path = (dir / "sphere.nii.gz").string();
  const auto status =
      volume::write_label_volume(volume::make_phantom(volume::PhantomShape::kSphere).volume, path);
  EXPECT_THAT(status, testing::IsOk());
  return path;
}

TEST(ReportHtml, WrittenBesideReportJson) {
  const fs::path dir = testing::scratch_dir("report_html_written");
  MeshParams params;
  params.surface = SurfaceMethod::kRepaired;
  auto result = run_pipeline(write_sphere(dir), params, {});
  ASSERT_THAT(result, testing::IsOk());
  ASSERT_THAT(write_results(*result, params, (dir / "out").string(), {}), testing::IsOk());
  ASSERT_TRUE(fs::exists(dir / "out" / "report.json"));
  const std::string html = testing::read_bytes(dir / "out" / "report.html");
  size_t delivered = 0;
  for (const auto& surface : result->surfaces) {
    if (!surface.is_output) continue;
    ++delivered;
    EXPECT_TRUE(absl::StrContains(html, cat(">", surface.statistics.triangles, "<")));
  }
  EXPECT_EQ(count(html, "<svg"), 1u);
  // The input named with its digest, and every delivered surface pictured.
  EXPECT_TRUE(absl::StrContains(html, "<td>sphere.nii.gz</td>"));
  const auto digest = digest::sha256_file((dir / "sphere.nii.gz").string());
  ASSERT_THAT(digest, testing::IsOk());
  EXPECT_TRUE(absl::StrContains(html, cat("<code>", *digest, "</code>")));
  EXPECT_EQ(count(html, "data:image/png;base64,"), 1 + delivered);
}

// Runs headless Chromium on `url` with `arguments`, in a fresh profile and
// HOME under `dir` so that no earlier run or user setting interferes, with
// its output in `dir`/`log`. Its exit status (124 when it timed out).
int run_chromium(const fs::path& dir, std::string_view log, std::string_view arguments,
                 std::string_view url) {
  const fs::path run_dir = dir / cat("run-", log);
  fs::create_directories(run_dir / "home");
  const std::string command =
      cat("HOME='", (run_dir / "home").string(), "' timeout 60 chromium --headless --no-sandbox ",
          "--disable-gpu --disable-dev-shm-usage --user-data-dir='", (run_dir / "profile").string(),
          "' ", arguments, " '", url, "' 2> '", (dir / log).string(), "'");
  return WEXITSTATUS(std::system(command.c_str()));
}

TEST(ReportHtml, RendersInHeadlessChromium) {
  ASSERT_EQ(std::system("command -v chromium > /dev/null 2>&1"), 0)
      << "chromium is not installed; scripts/install-deps.sh installs it";
  const fs::path dir = testing::scratch_dir("report_html_chromium");
  const fs::path page = dir / "report.html";
  testing::write_file(page, report_html(sample_report_with_volume(), box_pictures()));
  const std::string url = cat("file://", page.string());

  const fs::path dom_file = dir / "dom.html";
  ASSERT_EQ(run_chromium(dir, "dump-dom.log", cat("--dump-dom > '", dom_file.string(), "'"), url),
            0)
      << testing::read_bytes(dir / "dump-dom.log");
  const std::string dom = testing::read_bytes(dom_file);
  for (const char* text : {"liver", kEscapedHostileName, "failed: no surface &amp; no mask",
                           "17012.3", "31.42", "1.235", "4532", "</svg>"})
    EXPECT_TRUE(absl::StrContains(dom, text)) << text << " not in the rendered DOM";
  EXPECT_FALSE(absl::StrContains(absl::AsciiStrToLower(dom), "<script"));

  const fs::path png = dir / "report.png";
  ASSERT_EQ(run_chromium(
                dir, "screenshot.log",
                cat("--screenshot='", png.string(), "' --window-size=1200,1600 > /dev/null"), url),
            0)
      << testing::read_bytes(dir / "screenshot.log");
  ASSERT_TRUE(fs::exists(png)) << testing::read_bytes(dir / "screenshot.log");
  EXPECT_TRUE(absl::StartsWith(testing::read_bytes(png), "\x89PNG"));
  // A blank page of this size is about 12 KB.
  EXPECT_GT(fs::file_size(png), 30'000u);
  // The boxes' pictures were decoded and drawn: pixels of the liver's
  // colour, lit, where the page has no other of it but a small swatch.
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  size_t liver_pixels = 0;
  for (int y = 0; y < dims[1]; ++y) {
    for (int x = 0; x < dims[0]; ++x) {
      const int r = int(image->GetScalarComponentAsDouble(x, y, 0, 0));
      const int g = int(image->GetScalarComponentAsDouble(x, y, 0, 1));
      const int b = int(image->GetScalarComponentAsDouble(x, y, 0, 2));
      liver_pixels += r == 221 && g == 130 && b == 101;
    }
  }
  EXPECT_GT(liver_pixels, 5'000u);
}

}  // namespace
}  // namespace labelmesh
