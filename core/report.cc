#include "core/report.h"

#include <google/protobuf/util/json_util.h>

#include "core/text.h"

namespace labelmesh {

v1::InputSummary make_input_summary(const VolumeSummary& summary) {
  v1::InputSummary input;
  const auto& g = summary.geometry;
  input.set_format(std::string(volume::format_name(summary.format)));
  for (int axis = 0; axis < 3; ++axis) {
    input.add_dims(static_cast<uint32_t>(g.dims[axis]));
    input.add_spacing(g.spacing[axis]);
    input.add_origin(g.origin[axis] + 0.0);  // + 0.0 turns -0 into 0.
  }
  for (double d : g.direction) input.add_direction(d + 0.0);
  input.set_convention(std::string(kPatientConvention));
  input.set_voxel_type(summary.file_voxel_type);
  const double voxel_volume = g.voxel_volume();
  for (const auto& label : summary.statistics.labels) {
    auto* entry = input.add_labels();
    entry->set_label(label.label);
    entry->set_voxels(label.voxels);
    entry->set_volume_mm3(static_cast<double>(label.voxels) * voxel_volume);
  }
  input.set_background_voxels(summary.statistics.background_voxels);
  return input;
}

v1::MeshOptions make_options(const MeshParams& params) {
  v1::MeshOptions options;
  for (int32_t label : params.labels) options.add_labels(label);
  options.set_surface(v1::SURFACE_METHOD_MARCHING_CUBES);
  for (auto format : params.formats)
    options.add_formats(std::string(surface::surface_format_name(format)));
  options.set_max_voxels(params.limits.max_voxels);
  return options;
}

absl::StatusOr<MeshParams> params_from_options(const v1::MeshOptions& options) {
  MeshParams params;
  params.labels.assign(options.labels().begin(), options.labels().end());
  switch (options.surface()) {
    case v1::SURFACE_METHOD_UNSPECIFIED:
    case v1::SURFACE_METHOD_MARCHING_CUBES:
      params.surface = SurfaceMethod::kMarchingCubes;
      break;
    default:
      return absl::InvalidArgumentError("surface: unknown surface method");
  }
  if (!options.formats().empty()) {
    params.formats.clear();
    for (const auto& name : options.formats()) {
      auto format = surface::surface_format_from_name(name);
      if (!format) {
        return absl::InvalidArgumentError(
            cat("formats: '", name, "' is not one of stl, ply, obj, off, vtp"));
      }
      params.formats.push_back(*format);
    }
  }
  if (options.max_voxels() > 0) params.limits.max_voxels = options.max_voxels();
  return params;
}

v1::Report make_report(const MeshResult& result, const MeshParams& params) {
  v1::Report report;
  report.set_labelmesh_version(LABELMESH_VERSION);
  *report.mutable_options() = make_options(params);
  *report.mutable_input() = make_input_summary(result.input);
  for (const auto& surface : result.surfaces) {
    const auto& s = surface.statistics;
    auto* entry = report.add_surfaces();
    entry->set_label(surface.label);
    entry->set_stage(surface.stage);
    entry->set_nodes(s.nodes);
    entry->set_triangles(s.triangles);
    entry->set_min_angle_deg(s.min_angle_deg);
    entry->set_max_angle_deg(s.max_angle_deg);
    entry->set_boundary_edges(s.boundary_edges);
    entry->set_non_manifold_edges(s.non_manifold_edges);
    entry->set_non_manifold_vertices(s.non_manifold_vertices);
    entry->set_closed(s.closed);
    entry->set_manifold(s.manifold);
    entry->set_euler_characteristic(static_cast<int32_t>(s.euler_characteristic));
    entry->set_components(s.components);
    entry->set_volume_mm3(s.volume_mm3);
    entry->set_area_mm2(s.area_mm2);
    for (const auto& file : surface.files) entry->add_files(file);
  }
  for (const auto& stage : result.stages) {
    auto* entry = report.add_stages();
    entry->set_name(stage.name);
    entry->set_seconds(stage.seconds);
  }
  return report;
}

std::string to_json(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

std::string report_json(const MeshResult& result, const MeshParams& params) {
  return to_json(make_report(result, params));
}

}  // namespace labelmesh
