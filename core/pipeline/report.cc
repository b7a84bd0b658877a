// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/report.h"

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>

#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "core/job/job_options.h"
#include "core/pipeline/build_info.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

void set_categories(const quality::QualitySummary& q, v1::QualityCategories& categories) {
  categories.set_invalid(q.invalid);
  categories.set_very_bad(q.very_bad);
  categories.set_questionable(q.questionable);
  categories.set_good(q.good);
}

void add_refusals(const std::vector<MixedVolumeResult::Refusal>& refusals,
                  google::protobuf::RepeatedPtrField<v1::LabelWarning>& out) {
  for (const auto& refusal : refusals) {
    auto* item = out.Add();
    item->set_label(refusal.label);
    item->set_reason(refusal.reason);
  }
}

v1::VolumeMeshSummary make_mixed_summary(const MixedVolumeResult& mixed) {
  const auto& q = mixed.quality;
  v1::VolumeMeshSummary entry;
  entry.set_mesher(mixed.hexahedra_only ? "hex_grid" : "mixed_grid");
  entry.set_nodes(mixed.mesh.points.size());
  entry.set_hexahedra(q.hexahedra);
  entry.set_pyramids(q.pyramids);
  entry.set_prisms(q.wedges);
  entry.set_tetrahedra(q.tetrahedra);
  entry.set_steiner_points(mixed.figures.tetgen.steiner_points);
  if (q.tetra_summary.count > 0) {
    entry.set_tetra_quality_min(q.tetra_summary.min);
    entry.set_tetra_quality_mean(q.tetra_summary.mean);
    entry.set_min_dihedral_deg(q.tetra_summary.min_dihedral_deg);
    entry.set_max_dihedral_deg(q.tetra_summary.max_dihedral_deg);
  }
  if (mixed.mesh.size() > 0) {
    entry.set_jacobian_ratio_min(q.jacobian_ratio_min);
    entry.set_jacobian_ratio_mean(q.jacobian_ratio_mean);
  }
  if (q.pyramid_aspect_ratio_min) entry.set_pyramid_aspect_ratio_min(*q.pyramid_aspect_ratio_min);
  if (q.scaled_jacobian_min) entry.set_scaled_jacobian_min(*q.scaled_jacobian_min);
  entry.set_split_hexahedra(mixed.figures.layer.split_hexahedra);
  entry.set_hex_interior_size_mm(mixed.interior_mm);
  const auto& octants = mixed.figures.octree.octants;
  size_t levels = std::size(octants);
  while (levels > 0 && octants[levels - 1] == 0) --levels;
  for (size_t level = 0; level < levels; ++level) entry.add_octants_per_level(octants[level]);
  entry.set_balance_splits(mixed.figures.octree.balance_splits);
  entry.set_transition_octants(mixed.figures.octree.transition_octants);
  entry.set_boundary_node_distance_max_mm(mixed.figures.layer.boundary_distance_max_mm);
  add_refusals(mixed.tetrahedral_layer_labels, *entry.mutable_tetrahedral_layer_labels());
  add_refusals(mixed.labels_left_out, *entry.mutable_labels_left_out());
  entry.set_inverted(q.invalid);
  set_categories(q.cell_summary, *entry.mutable_categories());
  entry.set_enclosed_volume_mm3(q.volume_mm3);
  entry.set_surface_volume_mm3(mixed.surface_volume_mm3);
  if (mixed.surface_volume_mm3 > 0)
    entry.set_volume_change(q.volume_mm3 / mixed.surface_volume_mm3 - 1);
  entry.set_hex_size_mm(mixed.cell_mm);
  const auto& c = mixed.conformity;
  auto* conformity = entry.mutable_conformity_check();
  conformity->set_interior_faces(c.interior_faces);
  conformity->set_boundary_faces(c.boundary_faces);
  conformity->set_nonconforming_faces(c.nonconforming_faces);
  conformity->set_duplicate_points(c.duplicate_points);
  conformity->set_open_boundary_edges(c.open_boundary_edges);
  // Labels are meshed apart: each label's cells conform, labels share no nodes.
  entry.set_conforming(false);
  entry.set_seconds(mixed.seconds);
  for (const auto& file : mixed.files) entry.add_files(file);
  return entry;
}

void add_conforming_figures(const conforming::ConformingFigures& figures,
                            v1::VolumeMeshSummary& entry) {
  const auto& check = figures.conformity;
  auto* conformity = entry.mutable_conformity_check();
  conformity->set_interior_faces(check.interior_faces + check.interface_faces);
  conformity->set_boundary_faces(check.outer_faces);
  conformity->set_nonconforming_faces(check.overshared_faces);
  conformity->set_duplicate_points(check.duplicate_points);
  conformity->set_open_boundary_edges(check.open_boundary_edges);
  entry.set_enclosed_volume_mm3(check.label_volume_sum_mm3);
  entry.set_inverted(check.inverted_tetrahedra);
  auto* out = entry.mutable_conforming_figures();
  out->set_interfaces(check.interfaces);
  out->set_interface_faces(check.interface_faces);
  out->set_outer_faces(check.outer_faces);
  out->set_interface_offset_max_mm(figures.interfaces.max_offset_mm);
  out->set_volume_gap(check.volume_gap_fraction());
  out->set_crossing_repairs(figures.crossing_repairs);
  out->set_restored_points(figures.restored_points);
  out->set_staircase_only(figures.staircase_only);
  out->set_interface_points_slid(figures.slide.points_moved);
  out->set_below_slide_targets_before(figures.slide.tetrahedra_below_before);
  out->set_below_slide_targets_after(figures.slide.tetrahedra_below_after);
  out->set_outside_regions(figures.regions.outside_regions);
  out->set_thick_slice_axis(figures.thick_slices.axis);
  out->set_thick_slice_parts(static_cast<uint32_t>(figures.thick_slices.parts));
  out->set_interface_voxel_faces(figures.coarsening.interface_faces);
  for (double factor : figures.coarsening.factors) out->add_coarsening_factors(factor);
  for (const auto& label : figures.labels) {
    auto* l = out->add_labels();
    l->set_label(label.label);
    l->set_voxels(label.voxels);
    l->set_voxel_volume_mm3(label.voxel_volume_mm3);
    l->set_mesh_volume_mm3(label.mesh_volume_mm3);
    l->set_tetrahedra(label.tetrahedra);
    l->set_volume_change(label.volume_change());
  }
  const auto spread = conforming::volume_change_spread(figures.labels, kSmallLabelVoxels);
  out->set_volume_change_median(spread.median);
  out->set_volume_change_p90(spread.p90);
}

v1::VolumeMeshSummary make_volume_summary(const VolumeResult& volume) {
  v1::VolumeMeshSummary entry;
  entry.set_mesher(volume.mesher);
  entry.set_nodes(volume.mesh.points.size());
  entry.set_tetrahedra(volume.mesh.tetrahedra.size());
  entry.set_steiner_points(volume.steiner_points);
  const auto& q = volume.summary;
  if (q.count > 0) {
    entry.set_tetra_quality_min(q.min);
    entry.set_tetra_quality_mean(q.mean);
    entry.set_min_dihedral_deg(q.min_dihedral_deg);
    entry.set_max_dihedral_deg(q.max_dihedral_deg);
  }
  auto* categories = entry.mutable_categories();
  categories->set_invalid(q.invalid);
  categories->set_very_bad(q.very_bad);
  categories->set_questionable(q.questionable);
  categories->set_good(q.good);
  entry.set_conforming(volume.conforming.has_value());
  entry.set_seconds(volume.seconds);
  if (volume.conforming) add_conforming_figures(*volume.conforming, entry);
  if (volume.improvement) {
    const auto& before = volume.improvement->tetgen_summary;
    const auto& figures = volume.improvement->figures;
    auto* improvement = entry.mutable_improvement();
    improvement->set_tetgen_quality_min(before.count > 0 ? before.min : 0);
    improvement->set_tetgen_questionable(before.invalid + before.very_bad + before.questionable);
    improvement->set_flips_2_3(figures.flips_2_3);
    improvement->set_flips_3_2(figures.flips_3_2);
    improvement->set_vertices_moved(figures.vertices_moved);
    improvement->set_vertices_inserted(figures.vertices_inserted);
    improvement->set_slivers_peeled(figures.slivers_peeled);
    improvement->set_peeled_volume_mm3(figures.peeled_volume_mm3);
    improvement->set_peel_depth_mm(figures.peel_depth_mm);
    improvement->set_seconds(figures.seconds);
  }
  for (const auto& file : volume.files) entry.add_files(file);
  return entry;
}

void add_quality_figures(const SurfaceResult& surface, v1::SurfaceSummary& entry) {
  if (surface.self_intersections) entry.set_self_intersections(*surface.self_intersections);
  if (surface.distance_to_marching_cubes) {
    entry.set_hausdorff_mm(surface.distance_to_marching_cubes->hausdorff_mm);
    entry.set_mean_distance_mm(surface.distance_to_marching_cubes->mean_mm);
    for (double c : surface.distance_to_marching_cubes->hausdorff_at) entry.add_hausdorff_at(c);
  }
  if (surface.components) {
    entry.set_components_kept(surface.components->kept);
    entry.set_components_dropped(surface.components->dropped);
    entry.set_dropped_voxels(surface.components->dropped_voxels);
    entry.set_pruned_voxels(surface.components->pruned_voxels);
    entry.set_cavities_filled(surface.components->filled_cavities);
    entry.set_cavity_voxels_filled(surface.components->filled_voxels);
  }
  if (surface.repair) {
    const auto& r = *surface.repair;
    auto* repair = entry.mutable_repair();
    repair->set_degenerate_triangles_removed(r.degenerate_triangles_removed);
    repair->set_needles_before(r.needles_before);
    repair->set_caps_before(r.caps_before);
    repair->set_needles_after(r.needles_after);
    repair->set_caps_after(r.caps_after);
    repair->set_non_manifold_vertices_split(r.non_manifold_vertices_split);
    repair->set_holes_filled(r.holes_filled);
  }
  if (surface.error) entry.set_error(*surface.error);
  if (surface.axis_aligned_share) entry.set_axis_aligned_percent(100 * *surface.axis_aligned_share);
  if (surface.fidelity) {
    const auto& f = *surface.fidelity;
    auto* fidelity = entry.mutable_fidelity();
    fidelity->set_volume_tolerance_percent(100 * f.tolerance.volume_fraction);
    fidelity->set_hausdorff_tolerance_mm(f.tolerance.hausdorff_mm);
    fidelity->set_marching_cubes_volume_mm3(f.marching_cubes_volume_mm3);
    fidelity->set_thickness_voxels(f.thickness_voxels);
    fidelity->set_misclassified_tolerance_percent(100 * f.tolerance.misclassified_fraction);
    fidelity->set_misclassified_reach_voxels(f.tolerance.misclassified_reach_voxels);
    fidelity->set_hausdorff_tolerance_voxels(f.tolerance.hausdorff_voxels);
    fidelity->set_within_tolerance(f.within_tolerance());
    if (f.delivered < f.attempts.size())
      fidelity->set_delivered(method_name(f.attempts[f.delivered].method));
    for (const auto& a : f.attempts) {
      auto* attempt = fidelity->add_attempts();
      attempt->set_method(method_name(a.method));
      attempt->set_max_edge_mm(a.max_edge_mm);
      attempt->set_max_distance_mm(a.max_distance_mm);
      attempt->set_error(a.error);
      attempt->set_volume_change_percent(100 * a.volume_change);
      attempt->set_hausdorff_mm(a.hausdorff_mm);
      attempt->set_mean_distance_mm(a.mean_distance_mm);
      attempt->set_min_angle_deg(a.min_angle_deg);
      attempt->set_max_angle_deg(a.max_angle_deg);
      attempt->set_within_tolerance(a.within_tolerance);
      if (a.voxels) {
        const auto& v = *a.voxels;
        auto* voxels = attempt->mutable_voxels();
        voxels->set_volume_change_percent(100 * v.volume_change);
        voxels->set_boundary_voxels(v.boundary_voxels);
        voxels->set_misclassified(v.misclassified);
        voxels->set_misclassified_percent(100 * v.misclassified_fraction());
        voxels->set_farthest_misclassified_voxels(v.farthest_misclassified_voxels);
        voxels->set_hausdorff_voxels(v.hausdorff_voxels);
        voxels->set_axis_aligned_percent(100 * v.axis_aligned_share);
      }
    }
  }
  if (surface.poisson) {
    const auto& p = *surface.poisson;
    auto* poisson = entry.mutable_poisson();
    poisson->set_input_points(p.input_points);
    poisson->set_used_points(p.used_points);
    poisson->set_solver_iterations(static_cast<uint32_t>(p.solver_iterations));
    poisson->set_solve_seconds(p.solve_seconds);
    poisson->set_mesh_seconds(p.mesh_seconds);
    poisson->set_point_cell_mm(p.point_cell_mm);
    poisson->set_solved_in_halves(p.solved_in_halves);
  }
}

void set_concept(const volume::CodedConcept& from, v1::CodedConcept& to) {
  to.set_scheme(from.scheme);
  to.set_value(from.value);
  to.set_meaning(from.meaning);
}

// The file's description of `label`, if it has one.
void describe_label(int32_t label, const volume::LabelDescriptions& descriptions,
                    v1::LabelSummary& entry) {
  for (const auto& description : descriptions) {
    if (description.label != label) continue;
    entry.set_name(description.name);
    if (description.colour) {
      for (uint8_t c : *description.colour) entry.add_colour_rgb(c);
    }
    if (!description.category.empty()) set_concept(description.category, *entry.mutable_category());
    if (!description.type.empty()) set_concept(description.type, *entry.mutable_type());
    return;
  }
}

}  // namespace

v1::InputSummary make_input_summary(const VolumeSummary& summary) {
  v1::InputSummary input;
  const auto& g = summary.geometry;
  const auto& file = summary.file_geometry ? *summary.file_geometry : g;
  input.set_format(std::string(volume::format_name(summary.format)));
  for (int axis = 0; axis < 3; ++axis) {
    input.add_dims(static_cast<uint32_t>(file.dims[axis]));
    input.add_spacing(file.spacing[axis]);
    input.add_origin(file.origin[axis] + 0.0);  // + 0.0 turns -0 into 0.
    if (summary.file_geometry) {
      input.add_meshed_dims(static_cast<uint32_t>(g.dims[axis]));
      input.add_meshed_spacing(g.spacing[axis]);
      input.add_meshed_origin(g.origin[axis] + 0.0);
    }
  }
  for (double d : file.direction) input.add_direction(d + 0.0);
  input.set_convention(std::string(kPatientConvention));
  input.set_voxel_type(summary.file_voxel_type);
  const double voxel_volume = g.voxel_volume();
  for (const auto& label : summary.statistics.labels) {
    auto* entry = input.add_labels();
    entry->set_label(label.label);
    entry->set_voxels(label.voxels);
    entry->set_volume_mm3(static_cast<double>(label.voxels) * voxel_volume);
    describe_label(label.label, summary.descriptions, *entry);
  }
  input.set_background_voxels(summary.statistics.background_voxels);
  input.set_layers(summary.layers);
  input.set_file_name(summary.file_name);
  input.set_sha256(summary.sha256);
  for (int axis = 0; axis < 3; ++axis) {
    input.add_repeated_planes(static_cast<uint32_t>(summary.repeated_planes[axis]));
    input.add_drawn_spacing(g.spacing[axis] * summary.repeated_planes[axis]);
  }
  return input;
}
v1::Report make_report(const MeshResult& result, const MeshParams& params) {
  v1::Report report;
  report.set_labelmesh_version(LABELMESH_VERSION);
  *report.mutable_build() = build_info();
  *report.mutable_options() = make_options(params);
  *report.mutable_input() = make_input_summary(result.input);
  report.set_created_at(absl::FormatTime("%Y-%m-%dT%H:%M:%SZ", absl::Now(), absl::UTCTimeZone()));
  for (const auto& surface : result.surfaces) {
    const auto& s = surface.statistics;
    auto* entry = report.add_surfaces();
    entry->set_label(surface.label);
    entry->set_stage(surface.stage);
    entry->set_nodes(s.nodes);
    entry->set_triangles(s.triangles);
    entry->set_min_angle_deg(s.min_angle_deg);
    entry->set_max_angle_deg(s.max_angle_deg);
    entry->set_triangles_below_30_deg(s.triangles_below_30_deg);
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
    entry->set_output(surface.is_output);
    add_quality_figures(surface, *entry);
  }
  if (result.volume) *report.mutable_volume() = make_volume_summary(*result.volume);
  if (result.mixed) *report.mutable_volume() = make_mixed_summary(*result.mixed);
  if (report.has_volume()) {
    for (const auto& pair : result.touching_labels) {
      auto* entry = report.mutable_volume()->add_touching_labels();
      entry->set_first(pair.first);
      entry->set_second(pair.second);
      entry->set_voxel_faces(pair.faces);
    }
  }
  for (const auto& warning : result.warnings) {
    auto* entry = report.add_warnings();
    entry->set_label(warning.label);
    entry->set_reason(warning.reason);
  }
  report.set_files_frame(std::string(frame_name(params.frame)));
  for (const auto& file : result.scene_files) report.add_scene_files(file);
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

}  // namespace labelmesh
