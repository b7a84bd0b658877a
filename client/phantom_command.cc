// SPDX-License-Identifier: AGPL-3.0-or-later
// `labelmesh phantom SHAPE --out FILE`: synthetic volumes with known geometry.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "core/volume/phantom.h"
#include "core/volume/write_label_volume.h"

namespace labelmesh::client {
namespace {

struct PhantomOptions {
  std::string shape;
  std::string out;
  double scale = 1.0;
};

}  // namespace

CommandRunner add_phantom_command(CLI::App& app) {
  auto options = std::make_shared<PhantomOptions>();
  CLI::App* phantom =
      app.add_subcommand("phantom", "Write a synthetic label volume with known geometry");
  std::vector<std::string> shapes;
  for (auto name : volume::phantom_shape_names()) shapes.emplace_back(name);
  phantom->add_option("shape", options->shape, "Shape to draw")
      ->required()
      ->check(CLI::IsMember(shapes));
  phantom->add_option("--out", options->out, "Output volume; the extension picks the format")
      ->required();
  phantom->add_option("--scale", options->scale, "Multiply every length by this")
      ->check(CLI::Range(0.25, 8.0))
      ->capture_default_str();
  phantom->footer(kExitCodeHelp);
  return [options] {
    const auto shape = volume::phantom_shape_from_name(options->shape);
    const auto made = volume::make_phantom(*shape, options->scale);
    if (auto status = volume::write_label_volume(made.volume, options->out); !status.ok()) {
      std::fprintf(stderr, "labelmesh phantom: %s\n", std::string(status.message()).c_str());
      return exit_code_for(status);
    }
    const auto& d = made.volume.geometry.dims;
    std::printf("wrote %s: %s, %lld x %lld x %lld voxels\n", options->out.c_str(),
                options->shape.c_str(), static_cast<long long>(d[0]), static_cast<long long>(d[1]),
                static_cast<long long>(d[2]));
    for (const auto& truth : made.truth) {
      std::printf("  label %d: volume %.3f mm3, area %.3f mm2\n", truth.label, truth.volume_mm3,
                  truth.area_mm2);
    }
    return int{kExitSuccess};
  };
}

}  // namespace labelmesh::client
