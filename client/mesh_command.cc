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
  std::string surface = "mc";
  std::vector<std::string> formats{"stl", "vtp"};
  uint64_t max_voxels = volume::ReadLimits{}.max_voxels;
  bool json = false;
};

void print_summary(const MeshResult& result, const std::string& out_dir) {
  std::printf("%8s %-15s %9s %9s %8s %8s %6s %8s %14s\n", "label", "stage", "nodes", "triangles",
              "min_ang", "max_ang", "closed", "manifold", "volume (mm3)");
  for (const auto& s : result.surfaces) {
    const auto& st = s.statistics;
    std::printf("%8d %-15s %9u %9u %8.3f %8.3f %6s %8s %14.3f\n", s.label, s.stage.c_str(),
                st.nodes, st.triangles, st.min_angle_deg, st.max_angle_deg,
                st.closed ? "yes" : "no", st.manifold ? "yes" : "no", st.volume_mm3);
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
  mesh->add_option("--surface", options->surface, "Surface method: mc (Marching Cubes)")
      ->check(CLI::IsMember({"mc"}))
      ->capture_default_str();
  mesh->add_option("--formats", options->formats,
                   "Surface files per label: stl, ply, obj, off, vtp")
      ->delimiter(',')
      ->check(CLI::IsMember({"stl", "ply", "obj", "off", "vtp"}))
      ->capture_default_str();
  mesh->add_option("--max-voxels", options->max_voxels, "Refuse volumes with more voxels than this")
      ->capture_default_str();
  mesh->add_flag("--json", options->json,
                 "Print report.json to stdout instead of progress and a table");
  mesh->footer(kExitCodeHelp);
  return [options] {
    v1::MeshOptions proto;
    for (int32_t label : options->labels) proto.add_labels(label);
    proto.set_surface(v1::SURFACE_METHOD_MARCHING_CUBES);
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
