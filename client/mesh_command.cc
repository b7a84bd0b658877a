// SPDX-License-Identifier: AGPL-3.0-or-later
// `labelmesh mesh FILE --out DIR`: the whole pipeline, in this process.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/label_warnings.h"
#include "client/pipeline_options.h"
#include "client/report_table.h"
#include "client/terminal_progress.h"
#include "core/job/job_options.h"
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
    TerminalProgress progress(!options->json, true);
    RunContext context;
    context.progress = [&progress](const ProgressUpdate& update) {
      ProgressLine line;
      line.stage = std::string(update.stage);
      line.fraction = update.fraction;
      if (const LabelInProgress* label = update.label) {
        line.label = label->label;
        line.label_name = label->name;
        line.label_index = label->index;
        line.label_count = label->count;
        line.labels_done = label->done;
      }
      progress.update(line);
    };
    auto result = run_pipeline(options->path, *params, context);
    absl::Status status = result.status();
    if (status.ok()) status = write_results(*result, *params, options->out_dir, context);
    progress.clear();
    if (!status.ok()) {
      std::fprintf(stderr, "labelmesh mesh: %s\n", std::string(status.message()).c_str());
      return exit_code_for(status);
    }
    const v1::Report report = make_report(*result, *params);
    if (options->json) {
      std::printf("%s\n", to_json(report).c_str());
    } else {
      std::printf("%s", report_table(report).c_str());
      std::printf("meshes, report.json and report.html written to %s\n", options->out_dir.c_str());
    }
    print_label_warnings("mesh", report);
    return int{kExitSuccess};
  };
}

}  // namespace labelmesh::client
