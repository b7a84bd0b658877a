// SPDX-License-Identifier: AGPL-3.0-or-later
// `labelmesh info FILE [--json]`: what a volume holds and where it sits.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "core/pipeline/pipeline.h"
#include "core/pipeline/report.h"

namespace labelmesh::client {
namespace {

struct InfoOptions {
  std::string path;
  bool json = false;
  uint64_t max_voxels = volume::ReadLimits{}.max_voxels;
  std::string overlapping = "refuse";
};

// A name from the file, with anything a terminal could act on replaced.
std::string printable(const std::string& text) {
  std::string shown = text;
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return shown;
}

void print_text(const std::string& path, const v1::InputSummary& s) {
  std::printf("file         %s\n", path.c_str());
  std::printf("format       %s\n", s.format().c_str());
  std::printf("dims         %u x %u x %u\n", s.dims(0), s.dims(1), s.dims(2));
  std::printf("spacing      %.6g x %.6g x %.6g mm\n", s.spacing(0), s.spacing(1), s.spacing(2));
  std::printf("origin       %.6g %.6g %.6g mm\n", s.origin(0), s.origin(1), s.origin(2));
  std::printf(
      "direction    [%.6g %.6g %.6g; %.6g %.6g %.6g; %.6g %.6g %.6g] (columns = voxel axes)\n",
      s.direction(0), s.direction(1), s.direction(2), s.direction(3), s.direction(4),
      s.direction(5), s.direction(6), s.direction(7), s.direction(8));
  std::printf("convention   %s\n", s.convention().c_str());
  std::printf("voxel type   %s\n", s.voxel_type().c_str());
  if (s.layers() > 1)
    std::printf("layers       %u (overlapping segments kept apart)\n", s.layers());
  if (s.repeated_planes_size() == 3) {
    std::printf("drawn at     %.6g x %.6g x %.6g mm (planes repeated %u x %u x %u)\n",
                s.drawn_spacing(0), s.drawn_spacing(1), s.drawn_spacing(2), s.repeated_planes(0),
                s.repeated_planes(1), s.repeated_planes(2));
  }
  std::printf("background   %llu voxels\n", static_cast<unsigned long long>(s.background_voxels()));
  std::printf("labels       %d\n", s.labels_size());
  std::printf("  %10s %14s %16s  %s\n", "label", "voxels", "volume (mm3)", "name");
  for (const auto& label : s.labels()) {
    std::printf("  %10d %14llu %16.3f  %s\n", label.label(),
                static_cast<unsigned long long>(label.voxels()), label.volume_mm3(),
                printable(label.name()).c_str());
  }
}

}  // namespace

CommandRunner add_info_command(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* info = app.add_subcommand("info", "Show a label volume's geometry and labels");
  info->add_option("file", options->path,
                   "Label volume (.nii .nii.gz .mha .mhd .nrrd .nhdr .inr .inr.gz .vti, or a "
                   "DICOM SEG of any name)")
      ->required();
  info->add_flag("--json", options->json, "Print the summary as protobuf JSON (InputSummary)");
  info->add_option("--max-voxels", options->max_voxels, "Refuse volumes with more voxels than this")
      ->capture_default_str();
  info->add_option("--overlapping", options->overlapping,
                   "Overlapping segments (DICOM SEG, 3D Slicer): refuse the input naming them, or "
                   "separate: count each segment whole")
      ->check(CLI::IsMember({"refuse", "separate"}))
      ->capture_default_str();
  info->footer(kExitCodeHelp);
  return [options] {
    volume::ReadLimits limits;
    limits.max_voxels = options->max_voxels;
    limits.separate_overlapping = options->overlapping == "separate";
    auto summary = summarise_volume(options->path, limits, RunContext{});
    if (!summary.ok()) {
      std::fprintf(stderr, "labelmesh info: %s\n", std::string(summary.status().message()).c_str());
      return exit_code_for(summary.status());
    }
    const auto input = make_input_summary(*summary);
    if (options->json) {
      std::printf("%s\n", to_json(input).c_str());
    } else {
      print_text(options->path, input);
    }
    return int{kExitSuccess};
  };
}

}  // namespace labelmesh::client
