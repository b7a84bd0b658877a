// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/write_results.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "core/pipeline/output_names.h"
#include "core/pipeline/report.h"
#include "core/surface/write_surface.h"
#include "core/util/exception_status.h"
#include "core/util/stage_timer.h"
#include "core/util/text.h"
#include "core/volume_mesh/write_volume_mesh.h"

namespace labelmesh {

namespace {

absl::Status write_all(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                       const RunContext& context) {
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error) return absl::InternalError(cat(out_dir, ": cannot create the directory"));
  {
    StageTimer timer(result.stages, "write");
    // Only output stages are written; progress counts those.
    const auto outputs = std::count_if(result.surfaces.begin(), result.surfaces.end(),
                                       [](const SurfaceResult& s) { return s.is_output; });
    size_t done = 0;
    for (auto& surface : result.surfaces) {
      if (auto s = context.check_stop(); !s.ok()) return s;
      surface.files.clear();
      if (!surface.is_output) continue;
      for (auto format : params.formats) {
        const std::string name = cat(surface_file_stem(surface.label, result.input.descriptions),
                                     ".", surface::surface_format_name(format));
        const auto path = (std::filesystem::path(out_dir) / name).string();
        if (auto s = surface::write_surface(surface.mesh, path, format); !s.ok()) return s;
        surface.files.push_back(name);
      }
      context.report("write", double(++done) / double(outputs));
    }
  }
  if (result.volume) {
    StageTimer timer(result.stages, "write_volume");
    result.volume->files.clear();
    for (auto format : params.volume_formats) {
      const std::string name = cat("volume.", volume_mesh::volume_format_name(format));
      const auto path = (std::filesystem::path(out_dir) / name).string();
      if (auto s = volume_mesh::write_volume_mesh(result.volume->mesh, result.volume->quality, path,
                                                  format);
          !s.ok())
        return s;
      result.volume->files.push_back(name);
      // TetGen's pair: the .ele beside the .node.
      if (format == volume_mesh::VolumeFormat::kTetgen)
        result.volume->files.push_back("volume.ele");
    }
  }
  const auto report_path = (std::filesystem::path(out_dir) / "report.json").string();
  std::ofstream out(report_path);
  out << report_json(result, params);
  if (!out) return absl::InternalError(cat(report_path, ": could not write the report"));
  return absl::OkStatus();
}

}  // namespace

absl::Status write_results(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                           const RunContext& context) {
  try {
    return write_all(result, params, out_dir, context);
  } catch (...) {
    return current_exception_status(out_dir);
  }
}

}  // namespace labelmesh
