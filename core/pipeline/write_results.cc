// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/write_results.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>

#include "core/dicom/encapsulated_stl.h"
#include "core/mixed_mesh/write_mixed_mesh.h"
#include "core/pipeline/output_names.h"
#include "core/pipeline/report.h"
#include "core/pipeline/report_html.h"
#include "core/pipeline/surface_picture.h"
#include "core/surface/write_surface.h"
#include "core/util/exception_status.h"
#include "core/util/side_by_side.h"
#include "core/util/stage_timer.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/write_label_volume.h"
#include "core/volume_mesh/write_volume_mesh.h"

namespace labelmesh {

namespace {

std::string label_name(int32_t label, const volume::LabelDescriptions& descriptions) {
  for (const auto& description : descriptions)
    if (description.label == label) return description.name;
  return {};
}

// The whole job's files: every output surface in one scene, the label volume.
// The delivered surfaces in their label's colour, or, when the input gave
// none, in one of a few colours told apart easily.
std::vector<ColouredSurface> coloured_surfaces(const MeshResult& result) {
  static constexpr std::array<std::array<uint8_t, 3>, 8> kPalette{{{228, 26, 28},
                                                                   {55, 126, 184},
                                                                   {77, 175, 74},
                                                                   {152, 78, 163},
                                                                   {255, 127, 0},
                                                                   {166, 86, 40},
                                                                   {247, 129, 191},
                                                                   {153, 153, 153}}};
  std::vector<ColouredSurface> surfaces;
  for (const auto& surface : result.surfaces) {
    if (!surface.is_output || surface.mesh.triangles.empty()) continue;
    ColouredSurface coloured{surface.label, &surface.mesh, kPalette[surfaces.size() % 8]};
    const auto& s = surface.statistics;
    coloured.closed_outward = s.closed && s.manifold && s.consistently_wound && s.volume_mm3 > 0 &&
                              surface.self_intersections == uint64_t{0};
    for (const auto& description : result.input.descriptions) {
      if (description.label == surface.label && description.colour)
        coloured.rgb = *description.colour;
    }
    surfaces.push_back(coloured);
  }
  return surfaces;
}

// Each delivered surface as DICOM Encapsulated STL, one new series for the
// run, in the patient frame (LPS) whatever the other files' frame: DICOM's
// frame of reference is the patient's.
absl::Status write_dicom_surfaces(MeshResult& result, const MeshParams& params,
                                  const std::string& out_dir) {
  if (!params.dicom_surfaces) return absl::OkStatus();
  if (!result.input.dicom)
    return absl::InvalidArgumentError("formats: dcm needs a DICOM SEG input");
  const dicom::DicomSeries series = dicom::new_surface_series();
  int32_t instance = 0;
  for (auto& surface : result.surfaces) {
    if (!surface.is_output) continue;
    const std::string name =
        cat(surface_file_stem(surface.label, result.input.descriptions), ".dcm");
    const auto path = std::filesystem::path(out_dir) / name;
    const std::string title = label_name(surface.label, result.input.descriptions);
    // VTK writes the STL; its bytes go into the DICOM object.
    const auto stl_path = std::filesystem::path(out_dir) / cat(name, ".stl.part");
    if (auto s =
            surface::write_surface(surface.mesh, stl_path.string(), surface::SurfaceFormat::kStl,
                                   {surface.label, title, CoordinateFrame::kLps});
        !s.ok())
      return s;
    std::ifstream in(stl_path, std::ios::binary);
    const std::string stl((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const bool read = !in.bad() && stl.size() >= 84;  // header and triangle count
    in.close();
    std::error_code ignored;
    std::filesystem::remove(stl_path, ignored);
    if (!read) return absl::InternalError(cat(stl_path.string(), ": cannot read the STL back"));
    LABELMESH_RETURN_IF_ERROR(
        dicom::write_encapsulated_stl(stl, path.string(), *result.input.dicom, series, ++instance,
                                      title.empty() ? cat("label ", surface.label) : title));
    surface.files.push_back(name);
  }
  return absl::OkStatus();
}

absl::Status write_scene(MeshResult& result, const MeshParams& params, const std::string& out_dir) {
  result.scene_files.clear();
  for (auto format : params.scene_formats) {
    const std::string name(scene_file_name(format));
    const auto path = (std::filesystem::path(out_dir) / name).string();
    if (format == SceneFormat::kVtm) {
      std::vector<const surface::TriangleMesh*> meshes;
      std::vector<surface::SurfaceFileInfo> infos;
      for (const auto& surface : result.surfaces) {
        if (!surface.is_output) continue;
        meshes.push_back(&surface.mesh);
        infos.push_back(
            {surface.label, label_name(surface.label, result.input.descriptions), params.frame});
      }
      LABELMESH_RETURN_IF_ERROR(surface::write_surface_scene(meshes, infos, path));
      result.scene_files.push_back(name);
      // VTK writes block i to surfaces/surfaces_<i>.vtp, beside the file.
      for (size_t block = 0; block < meshes.size(); ++block) {
        const std::string piece = cat("surfaces/surfaces_", block, ".vtp");
        if (!std::filesystem::exists(std::filesystem::path(out_dir) / piece))
          return absl::InternalError(cat(path, ": VTK wrote no ", piece));
        result.scene_files.push_back(piece);
      }
      continue;
    }
    if (!result.label_image)
      return absl::InternalError(cat(path, ": the label volume was not kept"));
    volume::LabelVolume placed = *result.label_image;
    if (format == SceneFormat::kVti && params.frame == CoordinateFrame::kRas) {
      // The same voxels placed in RAS: origin and axis directions with x and y negated.
      auto& g = placed.geometry;
      g.origin = in_frame(g.origin, params.frame);
      for (int column = 0; column < 3; ++column) {
        const auto axis = in_frame(
            {g.direction[column], g.direction[3 + column], g.direction[6 + column]}, params.frame);
        for (int row = 0; row < 3; ++row) g.direction[3 * row + column] = axis[row];
      }
    }
    LABELMESH_RETURN_IF_ERROR(volume::write_label_volume(placed, path));
    result.scene_files.push_back(name);
  }
  return absl::OkStatus();
}

// Every file but the report: surfaces, scene, volume meshes.
absl::Status write_files(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                         const RunContext& context) {
  {
    StageTimer timer(result.stages, "write");
    // Only output stages are written; progress counts those.
    const auto outputs = std::count_if(result.surfaces.begin(), result.surfaces.end(),
                                       [](const SurfaceResult& s) { return s.is_output; });
    size_t done = 0;
    for (auto& surface : result.surfaces) {
      LABELMESH_RETURN_IF_ERROR(context.check_stop());
      surface.files.clear();
      if (!surface.is_output) continue;
      for (auto format : params.formats) {
        const std::string name = cat(surface_file_stem(surface.label, result.input.descriptions),
                                     ".", surface::surface_format_name(format));
        const auto path = (std::filesystem::path(out_dir) / name).string();
        const surface::SurfaceFileInfo info{
            surface.label, label_name(surface.label, result.input.descriptions), params.frame};
        LABELMESH_RETURN_IF_ERROR(surface::write_surface(surface.mesh, path, format, info));
        surface.files.push_back(name);
      }
      context.report("write", double(++done) / double(outputs));
    }
    LABELMESH_RETURN_IF_ERROR(write_dicom_surfaces(result, params, out_dir));
  }
  if (!params.scene_formats.empty()) {
    StageTimer timer(result.stages, "write_scene");
    LABELMESH_RETURN_IF_ERROR(write_scene(result, params, out_dir));
  }
  volume_mesh::VolumeFileInfo info;
  info.frame = params.frame;
  for (const auto& description : result.input.descriptions)
    if (!description.name.empty()) info.label_names[description.label] = description.name;
  // No file for a mesh of no cells: every label was left out.
  if (result.mixed && result.mixed->mesh.size() > 0) {
    StageTimer timer(result.stages, "write_volume");
    result.mixed->files.clear();
    for (auto format : params.volume_formats) {
      const std::string name = cat("volume.", volume_mesh::volume_format_name(format));
      const auto path = (std::filesystem::path(out_dir) / name).string();
      LABELMESH_RETURN_IF_ERROR(mixed_mesh::write_mixed_mesh(
          result.mixed->mesh, result.mixed->quality, path, format, info));
      result.mixed->files.push_back(name);
    }
  }
  if (result.volume) {
    StageTimer timer(result.stages, "write_volume");
    result.volume->files.clear();
    auto volume_info = info;
    std::vector<volume_mesh::InterfaceFace> interfaces;
    if (result.volume->conforming) {
      interfaces = volume_mesh::interface_faces(result.volume->mesh);
      volume_info.interfaces = &interfaces;
    }
    for (auto format : params.volume_formats) {
      const std::string name = cat("volume.", volume_mesh::volume_format_name(format));
      const auto path = (std::filesystem::path(out_dir) / name).string();
      LABELMESH_RETURN_IF_ERROR(volume_mesh::write_volume_mesh(
          result.volume->mesh, result.volume->quality, path, format, volume_info));
      result.volume->files.push_back(name);
      if (volume_info.interfaces != nullptr && format == volume_mesh::VolumeFormat::kVtu)
        result.volume->files.push_back(volume_mesh::interfaces_vtu_path(name));
      if (volume_info.interfaces != nullptr && format == volume_mesh::VolumeFormat::kXdmf)
        result.volume->files.push_back(volume_mesh::facets_xdmf_path(name));
      // TetGen's pair: the .ele beside the .node.
      if (format == volume_mesh::VolumeFormat::kTetgen)
        result.volume->files.push_back("volume.ele");
    }
  }
  return absl::OkStatus();
}

absl::Status write_all(MeshResult& result, const MeshParams& params, const std::string& out_dir,
                       const RunContext& context) {
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error) return absl::InternalError(cat(out_dir, ": cannot create the directory"));
  // The report's pictures are drawn while the files are written: they read
  // the delivered meshes, which writing leaves as they are.
  const std::vector<ColouredSurface> coloured = coloured_surfaces(result);
  SurfacePictures pictures;
  double picture_seconds = 0;
  absl::Status written;
  side_by_side(
      [&] {
        if (context.stop_requested()) return;
        const auto start = std::chrono::steady_clock::now();
        pictures = make_surface_pictures(coloured);
        picture_seconds = seconds_since(start);
      },
      [&] { written = write_files(result, params, out_dir, context); });
  LABELMESH_RETURN_IF_ERROR(written);
  add_stage_time(result.stages, "report_pictures", picture_seconds);
  const v1::Report report = make_report(result, params);
  const auto report_path = (std::filesystem::path(out_dir) / "report.json").string();
  std::ofstream out(report_path);
  out << to_json(report);
  if (!out) return absl::InternalError(cat(report_path, ": could not write the report"));
  const auto html_path = (std::filesystem::path(out_dir) / "report.html").string();
  std::ofstream html(html_path);
  html << report_html(report, pictures);
  if (!html) return absl::InternalError(cat(html_path, ": could not write the report"));
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
