// `labelmesh mesh FILE --out DIR`: the whole pipeline, in this process.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/terminal_progress.h"
#include "core/pipeline.h"
#include "core/report.h"
#include "core/text.h"

namespace labelmesh::client {
namespace {

struct MeshCommandOptions {
  std::string path;
  std::string out_dir;
  std::vector<int32_t> labels;
  std::string surface = "poisson";
  PoissonOptions poisson;
  std::string normals = "uniform";
  std::string point_reduction = "grid";
  bool keep_strands = false;
  std::string volume = "none";
  volume_mesh::TetgenParams tetgen;
  bool tet_split_boundary = false;
  std::vector<std::string> formats{"stl", "vtp"};
  uint64_t max_voxels = volume::ReadLimits{}.max_voxels;
  bool json = false;
};

// "-" for a figure the stage does not measure.
std::string optional_figure(bool present, double value, const char* format) {
  if (!present) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

void print_summary(const MeshResult& result, const std::string& out_dir) {
  std::printf("%8s %-15s %9s %9s %8s %8s %6s %8s %14s %9s %9s\n", "label", "stage", "nodes",
              "triangles", "min_ang", "max_ang", "closed", "manifold", "volume (mm3)", "self_int",
              "hausdorff");
  for (const auto& s : result.surfaces) {
    const auto& st = s.statistics;
    const auto& distance = s.distance_to_marching_cubes;
    std::printf("%8d %-15s %9u %9u %8.3f %8.3f %6s %8s %14.3f %9s %9s\n", s.label, s.stage.c_str(),
                st.nodes, st.triangles, st.min_angle_deg, st.max_angle_deg,
                st.closed ? "yes" : "no", st.manifold ? "yes" : "no", st.volume_mm3,
                optional_figure(s.self_intersections.has_value(),
                                double(s.self_intersections.value_or(0)), "%.0f")
                    .c_str(),
                optional_figure(distance.has_value(), distance ? distance->hausdorff_mm : 0, "%.3f")
                    .c_str());
  }
  if (result.volume) {
    const auto& v = *result.volume;
    const auto& q = v.summary;
    std::printf(
        "volume (%s): %zu nodes, %zu tetrahedra; quality Q min %.3f mean %.3f; dihedral %.1f-%.1f "
        "deg; invalid %lld, very bad %lld, questionable %lld, good %lld\n",
        v.mesher.c_str(), v.mesh.points.size(), v.mesh.tetrahedra.size(), q.count ? q.min : 0,
        q.mean, q.count ? q.min_dihedral_deg : 0, q.count ? q.max_dihedral_deg : 0,
        (long long)q.invalid, (long long)q.very_bad, (long long)q.questionable, (long long)q.good);
  }
  std::printf("meshes and report.json written to %s\n", out_dir.c_str());
}

}  // namespace

CommandRunner add_mesh_command(CLI::App& app) {
  auto options = std::make_shared<MeshCommandOptions>();
  CLI::App* mesh = app.add_subcommand("mesh", "Mesh a label volume in this process");
  mesh->add_option("file", options->path,
                   "Label volume (.nii .nii.gz .mha .mhd .nrrd .nhdr .inr .inr.gz .vti)")
      ->required();
  mesh->add_option("--out", options->out_dir, "Output directory (created if missing)")->required();
  mesh->add_option("--labels", options->labels,
                   "Labels to mesh, e.g. 1,3 (default: every non-zero label)")
      ->delimiter(',');
  mesh->add_option("--surface", options->surface,
                   "Surface method: mc (Marching Cubes), repaired (MC repaired with CGAL), "
                   "poisson (repaired MC, then CGAL Poisson reconstruction)")
      ->check(CLI::IsMember({"mc", "repaired", "poisson"}))
      ->capture_default_str();
  auto& poisson = options->poisson;
  mesh->add_option("--min-angle", poisson.min_angle_deg,
                   "Poisson: smallest triangle angle, degrees, at most 30")
      ->capture_default_str();
  mesh->add_option("--max-edge", poisson.max_edge_voxels, "Poisson: longest triangle edge, voxels")
      ->capture_default_str();
  mesh->add_option("--max-distance", poisson.max_distance_voxels,
                   "Poisson: surface mesher distance bound, voxels")
      ->capture_default_str();
  mesh->add_option("--min-component-voxels", poisson.min_component_voxels,
                   "Drop connected components of a label with fewer voxels (repaired, poisson)")
      ->capture_default_str();
  mesh->add_flag("--keep-strands", options->keep_strands,
                 "Keep strands one voxel thick (repaired, poisson); by default they are pruned");
  mesh->add_option("--smoothing-iterations", poisson.smoothing.iterations,
                   "Poisson: windowed-sinc smoothing of the repaired surface before "
                   "reconstruction, filter iterations (0: off)")
      ->capture_default_str();
  mesh->add_option("--smoothing-pass-band", poisson.smoothing.pass_band,
                   "Poisson: smoothing pass band in (0, 2); lower smooths more")
      ->capture_default_str();
  mesh->add_option("--normals", options->normals,
                   "Poisson: vertex normals from incident triangles, uniform or area weighted")
      ->check(CLI::IsMember({"uniform", "area"}))
      ->capture_default_str();
  mesh->add_option("--point-reduction", options->point_reduction,
                   "Poisson: thin the oriented points with grid, hierarchy or none")
      ->check(CLI::IsMember({"grid", "hierarchy", "none"}))
      ->capture_default_str();
  mesh->add_option("--point-cell", poisson.point_cell_voxels,
                   "Poisson: grid cell of the point reduction, voxels")
      ->capture_default_str();
  mesh->add_option("--volume", options->volume,
                   "Volume mesh: none, or tet (TetGen on each label's output surface)")
      ->check(CLI::IsMember({"none", "tet"}))
      ->capture_default_str();
  auto& tetgen = options->tetgen;
  mesh->add_option("--tet-radius-edge", tetgen.radius_edge_ratio,
                   "Tet: largest circumradius / shortest edge (TetGen -q), at least 1")
      ->capture_default_str();
  mesh->add_option("--tet-min-dihedral", tetgen.min_dihedral_deg,
                   "Tet: smallest dihedral angle TetGen refines for, degrees (at most 30)")
      ->capture_default_str();
  mesh->add_option("--tet-max-volume", tetgen.max_volume_mm3,
                   "Tet: largest tetrahedron volume, mm^3 (TetGen -a); 0 for no bound")
      ->capture_default_str();
  mesh->add_flag("--tet-split-boundary", options->tet_split_boundary,
                 "Tet: let TetGen add points on the surface (by default it keeps the surface "
                 "triangles, -Y)");
  mesh->add_option("--formats", options->formats,
                   "Files to write: surfaces per label (stl, ply, obj, off, vtp) and, with "
                   "--volume, one volume mesh (vtu, msh, mesh, inp, node); default stl,vtp; "
                   "with --volume and no volume format listed, vtu")
      ->delimiter(',')
      ->check(
          CLI::IsMember({"stl", "ply", "obj", "off", "vtp", "vtu", "msh", "mesh", "inp", "node"}));
  mesh->add_option("--max-voxels", options->max_voxels, "Refuse volumes with more voxels than this")
      ->capture_default_str();
  mesh->add_flag("--json", options->json,
                 "Print report.json to stdout instead of progress and a table");
  mesh->footer(kExitCodeHelp);
  return [options] {
    v1::MeshOptions proto;
    for (int32_t label : options->labels) proto.add_labels(label);
    proto.set_surface(options->surface == "mc"         ? v1::SURFACE_METHOD_MARCHING_CUBES
                      : options->surface == "repaired" ? v1::SURFACE_METHOD_REPAIRED
                                                       : v1::SURFACE_METHOD_POISSON);
    const auto& poisson = options->poisson;
    proto.set_min_angle_deg(poisson.min_angle_deg);
    proto.set_max_edge_voxels(poisson.max_edge_voxels);
    proto.set_max_distance_voxels(poisson.max_distance_voxels);
    proto.set_min_component_voxels(poisson.min_component_voxels);
    proto.set_point_cell_voxels(poisson.point_cell_voxels);
    proto.set_prune_strands(!options->keep_strands);
    proto.set_smoothing_iterations(poisson.smoothing.iterations);
    proto.set_smoothing_pass_band(poisson.smoothing.pass_band);

    proto.set_normals(options->normals == "area" ? v1::NORMAL_WEIGHTING_AREA
                                                 : v1::NORMAL_WEIGHTING_UNIFORM);
    proto.set_point_reduction(options->point_reduction == "hierarchy"
                                  ? v1::POINT_REDUCTION_HIERARCHY
                              : options->point_reduction == "none" ? v1::POINT_REDUCTION_NONE
                                                                   : v1::POINT_REDUCTION_GRID);
    if (options->volume == "tet") {
      proto.set_volume(v1::VOLUME_METHOD_TETGEN);
      proto.set_tet_radius_edge(options->tetgen.radius_edge_ratio);
      proto.set_tet_min_dihedral_deg(options->tetgen.min_dihedral_deg);
      proto.set_tet_max_volume_mm3(options->tetgen.max_volume_mm3);
      proto.set_tet_keep_boundary(!options->tet_split_boundary);
    }
    for (const auto& format : options->formats) proto.add_formats(format);
    proto.set_max_voxels(options->max_voxels);
    auto params = params_from_options(proto);
    if (!params.ok()) {
      std::fprintf(stderr, "labelmesh mesh: %s\n", std::string(params.status().message()).c_str());
      return int{kExitUsage};
    }
    TerminalProgress progress(!options->json);
    RunContext context;
    context.progress = [&progress](std::string_view stage, double fraction) {
      progress.update(stage, fraction);
    };
    auto result = run_pipeline(options->path, *params, context);
    absl::Status status = result.status();
    if (status.ok()) status = write_results(*result, *params, options->out_dir, context);
    progress.update("", 0);
    if (!status.ok()) {
      std::fprintf(stderr, "labelmesh mesh: %s\n", std::string(status.message()).c_str());
      return exit_code_for(status);
    }
    if (options->json) {
      std::printf("%s\n", report_json(*result, *params).c_str());
    } else {
      print_summary(*result, options->out_dir);
    }
    return int{kExitSuccess};
  };
}

}  // namespace labelmesh::client
