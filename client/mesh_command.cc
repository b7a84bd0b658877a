// SPDX-License-Identifier: AGPL-3.0-or-later
// `labelmesh mesh FILE --out DIR`: the whole pipeline, in this process.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/label_warnings.h"
#include "client/pipeline_options.h"
#include "client/terminal_progress.h"
#include "core/pipeline/job_options.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"
#include "core/pipeline/write_results.h"
#include "core/util/text.h"

namespace labelmesh::client {
namespace {

struct MeshCommandOptions {
  std::string path;
  std::string out_dir;
  PipelineFlags pipeline;
  bool json = false;
  unsigned threads = 0;
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
    if (s.error) {
      std::printf("%8d %-15s not delivered: %s\n", s.label, s.stage.c_str(), s.error->c_str());
      continue;
    }
    if (s.components && s.components->kept == 0) {
      std::printf(
          "%8d %-15s every component under --min-component-voxels: %u dropped, no surface\n",
          s.label, s.stage.c_str(), s.components->dropped);
      continue;
    }
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
                   "Label volume (.nii .nii.gz .mha .mhd .nrrd .nhdr .inr .inr.gz .vti .dcm)")
      ->required();
  mesh->add_option("--out", options->out_dir, "Output directory (created if missing)")->required();
  add_pipeline_flags(*mesh, options->pipeline);
  mesh->add_option("--threads", options->threads,
                   "Labels meshed at once (0: one per core); the output is the same for any")
      ->capture_default_str();
  mesh->add_flag("--json", options->json,
                 "Print report.json to stdout instead of progress and a table");
  mesh->footer(kExitCodeHelp);
  return [options] {
    const auto proto = to_mesh_options(options->pipeline);
    auto params =
        proto.ok() ? params_from_options(*proto) : absl::StatusOr<MeshParams>(proto.status());
    if (!params.ok()) {
      std::fprintf(stderr, "labelmesh mesh: %s\n", std::string(params.status().message()).c_str());
      return int{kExitUsage};
    }
    params->threads = options->threads;
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
    print_label_warnings("mesh", make_report(*result, *params));
    return int{kExitSuccess};
  };
}

}  // namespace labelmesh::client
