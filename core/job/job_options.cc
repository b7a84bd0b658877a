// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/job_options.h"

#include <algorithm>
#include <cmath>

#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

v1::SurfaceMethod to_proto(SurfaceMethod method) {
  switch (method) {
    case SurfaceMethod::kMarchingCubes:
      return v1::SURFACE_METHOD_MARCHING_CUBES;
    case SurfaceMethod::kRepaired:
      return v1::SURFACE_METHOD_REPAIRED;
    case SurfaceMethod::kPoisson:
      return v1::SURFACE_METHOD_POISSON;
    case SurfaceMethod::kNet:
      return v1::SURFACE_METHOD_NET;
  }
  return v1::SURFACE_METHOD_UNSPECIFIED;
}

v1::PointReduction to_proto(surface::PointReduction reduction) {
  switch (reduction) {
    case surface::PointReduction::kGrid:
      return v1::POINT_REDUCTION_GRID;
    case surface::PointReduction::kHierarchy:
      return v1::POINT_REDUCTION_HIERARCHY;
    case surface::PointReduction::kNone:
      return v1::POINT_REDUCTION_NONE;
  }
  return v1::POINT_REDUCTION_UNSPECIFIED;
}

// Sizing finer than this, in voxels, the voxels cannot tell apart; finer
// still only multiplies the points (a tenth of a voxel on a small sphere ran
// a worker to its time limit at 1.2 GB).
constexpr double kFinestEdgeVoxels = 0.5;
constexpr double kFinestDistanceVoxels = 0.05;
constexpr double kCoarsestVoxels = 1000;

// A sizing length in voxels: finite and in [finest, kCoarsestVoxels].
absl::Status check_voxels(std::string_view field, double value, double finest) {
  if (std::isfinite(value) && value >= finest && value <= kCoarsestVoxels) return absl::OkStatus();
  return absl::InvalidArgumentError(
      cat(field, ": ", value, " is outside [", finest, ", ", kCoarsestVoxels, "] voxels"));
}

// Lengths in mm beyond a metre are mistakes.
constexpr double kMaxLengthMm = 1000;
// No label is this many voxels thick.
constexpr double kMaxThicknessVoxels = 100000;
// One entry per label is plenty; the bounds keep a job record small.
constexpr int kMaxLabelSizings = 1000;
constexpr int kMaxLabels = 10000;
constexpr int kMaxLabelNames = 10000;
constexpr size_t kMaxLabelNameBytes = 128;
// Each format at most once, but a client may repeat itself a little.
constexpr int kMaxFormatEntries = 32;
// The format name of MeshParams::dicom_surfaces.
constexpr std::string_view kDicomSurfaceFormat = "dcm";

absl::Status check_millimetres(std::string_view field, double value) {
  if (std::isfinite(value) && value > 0 && value <= kMaxLengthMm) return absl::OkStatus();
  return absl::InvalidArgumentError(
      cat(field, ": ", value, " is not a length in (0, ", kMaxLengthMm, "] mm"));
}

absl::Status read_guard_options(const v1::MeshOptions& options, GuardOptions& guard) {
  auto percent = [](std::string_view field, double value) {
    if (std::isfinite(value) && value > 0 && value <= 100) return absl::OkStatus();
    return absl::InvalidArgumentError(cat(field, ": ", value, " is outside (0, 100] percent"));
  };
  if (options.has_volume_tolerance_percent()) {
    guard.volume_percent = options.volume_tolerance_percent();
    LABELMESH_RETURN_IF_ERROR(percent("volume_tolerance_percent", guard.volume_percent));
  }
  if (options.has_small_volume_tolerance_percent()) {
    guard.small_volume_percent = options.small_volume_tolerance_percent();
    LABELMESH_RETURN_IF_ERROR(
        percent("small_volume_tolerance_percent", guard.small_volume_percent));
  }
  if (options.has_hausdorff_tolerance_mm()) {
    guard.hausdorff_mm = options.hausdorff_tolerance_mm();
    // 0 asks for the default (the drawn spacing).
    if (guard.hausdorff_mm != 0) {
      LABELMESH_RETURN_IF_ERROR(check_millimetres("hausdorff_tolerance_mm", guard.hausdorff_mm));
    }
  }
  if (options.has_fall_back()) guard.fall_back = options.fall_back();
  if (options.has_strict()) guard.strict = options.strict();
  return absl::OkStatus();
}

// Each label named once, not the background, a short name of no control
// characters and a colour of three components or none.
absl::Status read_label_names(const v1::MeshOptions& options, volume::LabelDescriptions& names) {
  if (options.label_names_size() > kMaxLabelNames)
    return absl::InvalidArgumentError(
        cat("label_names: ", options.label_names_size(), " entries; at most ", kMaxLabelNames));
  for (const auto& entry : options.label_names()) {
    const std::string field = cat("label_names: label ", entry.label());
    if (entry.label() <= 0) return absl::InvalidArgumentError(cat(field, ": must be positive"));
    if (entry.name().size() > kMaxLabelNameBytes)
      return absl::InvalidArgumentError(cat(field, ": name over ", kMaxLabelNameBytes, " bytes"));
    if (std::any_of(entry.name().begin(), entry.name().end(),
                    [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
      return absl::InvalidArgumentError(cat(field, ": name holds control characters"));
    if (entry.colour_rgb_size() != 0 && entry.colour_rgb_size() != 3)
      return absl::InvalidArgumentError(cat(field, ": colour_rgb needs three values or none"));
    volume::LabelDescription named = volume::named_label(entry.label(), entry.name());
    if (entry.colour_rgb_size() == 3) {
      std::array<uint8_t, 3> colour{};
      for (int c = 0; c < 3; ++c) {
        if (entry.colour_rgb(c) > 255)
          return absl::InvalidArgumentError(cat(field, ": colour_rgb values are 0-255"));
        colour[c] = static_cast<uint8_t>(entry.colour_rgb(c));
      }
      named.colour = colour;
    }
    for (const auto& earlier : names) {
      if (earlier.label == named.label)
        return absl::InvalidArgumentError(cat(field, ": named more than once"));
    }
    names.push_back(std::move(named));
  }
  return absl::OkStatus();
}

absl::Status read_poisson_options(const v1::MeshOptions& options, PoissonOptions& poisson) {
  if (options.has_min_angle_deg()) {
    poisson.min_angle_deg = options.min_angle_deg();
    // CGAL's surface mesher terminates for angle bounds up to 30 degrees.
    if (!(poisson.min_angle_deg > 0 && poisson.min_angle_deg <= 30)) {
      return absl::InvalidArgumentError(
          cat("min_angle_deg: ", poisson.min_angle_deg, " is outside (0, 30]"));
    }
  }
  if (options.has_max_edge_voxels()) {
    poisson.max_edge_voxels = options.max_edge_voxels();
    LABELMESH_RETURN_IF_ERROR(
        check_voxels("max_edge_voxels", poisson.max_edge_voxels, kFinestEdgeVoxels));
  }
  if (options.has_max_distance_voxels()) {
    poisson.max_distance_voxels = options.max_distance_voxels();
    if (auto s =
            check_voxels("max_distance_voxels", poisson.max_distance_voxels, kFinestDistanceVoxels);
        !s.ok())
      return s;
  }
  if (options.has_max_edge_mm()) {
    poisson.max_edge_mm = options.max_edge_mm();
    LABELMESH_RETURN_IF_ERROR(check_millimetres("max_edge_mm", poisson.max_edge_mm));
  }
  if (options.has_max_distance_mm()) {
    poisson.max_distance_mm = options.max_distance_mm();
    LABELMESH_RETURN_IF_ERROR(check_millimetres("max_distance_mm", poisson.max_distance_mm));
  }
  if (options.has_adapt_to_thickness()) poisson.adapt_to_thickness = options.adapt_to_thickness();
  if (options.has_poisson_min_thickness_voxels()) {
    poisson.min_thickness_voxels = options.poisson_min_thickness_voxels();
    if (!(poisson.min_thickness_voxels >= 0 && poisson.min_thickness_voxels <= kMaxThicknessVoxels))
      return absl::InvalidArgumentError(
          cat("poisson_min_thickness_voxels: ", poisson.min_thickness_voxels, " is outside [0, ",
              kMaxThicknessVoxels, "] voxels"));
  }
  if (options.label_sizing_size() > kMaxLabelSizings)
    return absl::InvalidArgumentError(
        cat("label_sizing: ", options.label_sizing_size(), " entries; at most ", kMaxLabelSizings));
  for (const auto& entry : options.label_sizing()) {
    if (entry.label() == 0)
      return absl::InvalidArgumentError("label_sizing: label 0 is the background");
    for (const auto& earlier : poisson.label_sizing) {
      if (earlier.label == entry.label())
        return absl::InvalidArgumentError(
            cat("label_sizing: label ", entry.label(), " is given more than once"));
    }
    if (!(entry.max_edge_mm() >= 0 && entry.max_edge_mm() <= kMaxLengthMm) ||
        !(entry.max_distance_mm() >= 0 && entry.max_distance_mm() <= kMaxLengthMm))
      return absl::InvalidArgumentError(cat("label_sizing: label ", entry.label(),
                                            ": lengths must be in [0, ", kMaxLengthMm, "] mm"));
    poisson.label_sizing.push_back({entry.label(), entry.max_edge_mm(), entry.max_distance_mm()});
  }
  if (options.has_prune_strands()) poisson.prune_strands = options.prune_strands();
  if (options.has_smoothing_iterations()) {
    poisson.smoothing.iterations = options.smoothing_iterations();
    if (poisson.smoothing.iterations < 0 || poisson.smoothing.iterations > 200) {
      return absl::InvalidArgumentError(
          cat("smoothing_iterations: ", poisson.smoothing.iterations, " is outside 0..200"));
    }
  }
  if (options.has_smoothing_pass_band()) {
    poisson.smoothing.pass_band = options.smoothing_pass_band();
    if (!(poisson.smoothing.pass_band > 0 && poisson.smoothing.pass_band < 2)) {
      return absl::InvalidArgumentError(
          cat("smoothing_pass_band: ", poisson.smoothing.pass_band, " is outside (0, 2)"));
    }
  }

  if (options.has_min_component_voxels())
    poisson.min_component_voxels = options.min_component_voxels();
  if (options.has_point_cell_voxels()) {
    poisson.point_cell_voxels = options.point_cell_voxels();
    // max_points bounds what a fine cell keeps.
    LABELMESH_RETURN_IF_ERROR(check_voxels("point_cell_voxels", poisson.point_cell_voxels, 0.01));
  }
  switch (options.normals()) {
    case v1::NORMAL_WEIGHTING_UNSPECIFIED:
    case v1::NORMAL_WEIGHTING_UNIFORM:
      poisson.normals = surface::NormalWeighting::kUniform;
      break;
    case v1::NORMAL_WEIGHTING_AREA:
      poisson.normals = surface::NormalWeighting::kArea;
      break;
    default:
      return absl::InvalidArgumentError("normals: unknown weighting");
  }
  if (options.has_point_cluster_size()) {
    poisson.point_cluster_size = options.point_cluster_size();
    if (poisson.point_cluster_size < 1 || poisson.point_cluster_size > surface::kMaxClusterSize) {
      return absl::InvalidArgumentError(cat("point_cluster_size: ", poisson.point_cluster_size,
                                            " is outside 1..", surface::kMaxClusterSize));
    }
  }
  if (options.has_max_points()) {
    poisson.max_points = options.max_points();
    LABELMESH_RETURN_IF_ERROR(surface::check_point_count("max_points", poisson.max_points));
  }
  if (options.has_split_points()) {
    poisson.split_points = options.split_points();
    LABELMESH_RETURN_IF_ERROR(surface::check_point_count("split_points", poisson.split_points));
  }
  switch (options.point_reduction()) {
    case v1::POINT_REDUCTION_UNSPECIFIED:
    case v1::POINT_REDUCTION_GRID:
      poisson.point_reduction = surface::PointReduction::kGrid;
      break;
    case v1::POINT_REDUCTION_HIERARCHY:
      poisson.point_reduction = surface::PointReduction::kHierarchy;
      break;
    case v1::POINT_REDUCTION_NONE:
      poisson.point_reduction = surface::PointReduction::kNone;
      break;
    default:
      return absl::InvalidArgumentError("point_reduction: unknown method");
  }
  return absl::OkStatus();
}

absl::Status read_volume_options(const v1::MeshOptions& options, MeshParams& params) {
  switch (options.volume()) {
    case v1::VOLUME_METHOD_UNSPECIFIED:
    case v1::VOLUME_METHOD_NONE:
      params.volume = VolumeMethod::kNone;
      break;
    case v1::VOLUME_METHOD_TETGEN:
      params.volume = VolumeMethod::kTetgen;
      break;
    case v1::VOLUME_METHOD_MIXED:
      params.volume = VolumeMethod::kMixed;
      break;
    case v1::VOLUME_METHOD_HEX:
      params.volume = VolumeMethod::kHex;
      break;
    case v1::VOLUME_METHOD_CONFORMING:
      params.volume = VolumeMethod::kConforming;
      break;
    default:
      return absl::InvalidArgumentError("volume: unknown volume method");
  }
  if (options.has_conforming_max_interface_faces())
    params.conforming_max_interface_faces = options.conforming_max_interface_faces();
  if (options.has_mesh_on_drawn_grid()) params.mesh_on_drawn_grid = options.mesh_on_drawn_grid();
  if (options.has_hex_size_mm()) params.hex_size_mm = options.hex_size_mm();
  if (!(params.hex_size_mm == 0 || (params.hex_size_mm >= 0.05 && params.hex_size_mm <= 1000)))
    return absl::InvalidArgumentError(
        cat("hex_size_mm: ", params.hex_size_mm, " is neither 0 nor in [0.05, 1000]"));
  if (options.has_hex_interior_size_mm())
    params.hex_interior_size_mm = options.hex_interior_size_mm();
  if (!(params.hex_interior_size_mm == 0 ||
        (params.hex_interior_size_mm > 0 && params.hex_interior_size_mm <= 1000)))
    return absl::InvalidArgumentError(cat("hex_interior_size_mm: ", params.hex_interior_size_mm,
                                          " is neither 0 nor in (0, 1000]"));
  if (params.hex_interior_size_mm > 0 && params.hex_size_mm > 0 &&
      params.hex_interior_size_mm < 2 * params.hex_size_mm)
    return absl::InvalidArgumentError(cat("hex_interior_size_mm: ", params.hex_interior_size_mm,
                                          " is less than twice hex_size_mm (", params.hex_size_mm,
                                          "), so no octant is coarser"));
  auto& tetgen = params.tetgen;
  if (options.has_tet_radius_edge()) tetgen.radius_edge_ratio = options.tet_radius_edge();
  if (options.has_tet_min_dihedral_deg()) tetgen.min_dihedral_deg = options.tet_min_dihedral_deg();
  if (options.has_tet_max_volume_mm3()) tetgen.max_volume_mm3 = options.tet_max_volume_mm3();
  if (options.has_tet_keep_boundary()) tetgen.keep_boundary = options.tet_keep_boundary();
  if (options.has_tet_max_dihedral_deg()) tetgen.max_dihedral_deg = options.tet_max_dihedral_deg();
  if (options.has_tet_improve_quality())
    params.improve.target_quality = options.tet_improve_quality();
  if (params.volume == VolumeMethod::kNone) return absl::OkStatus();
  // TetGen's ranges, as every TetGen run checks them: a job is refused here,
  // before any surface work is done.
  LABELMESH_RETURN_IF_ERROR(volume_mesh::check_tetgen_params(tetgen));
  if (!(params.improve.target_quality >= 0 && params.improve.target_quality < 1))
    return absl::InvalidArgumentError(
        cat("tet_improve_quality: ", params.improve.target_quality, " is outside [0, 1)"));
  return absl::OkStatus();
}

}  // namespace

v1::MeshOptions make_options(const MeshParams& params) {
  v1::MeshOptions options;
  for (int32_t label : params.labels) options.add_labels(label);
  options.set_surface(to_proto(params.surface));
  const PoissonOptions& poisson = params.poisson;
  options.set_min_angle_deg(poisson.min_angle_deg);
  options.set_max_edge_voxels(poisson.max_edge_voxels);
  options.set_max_distance_voxels(poisson.max_distance_voxels);
  options.set_min_component_voxels(poisson.min_component_voxels);
  options.set_normals(poisson.normals == surface::NormalWeighting::kArea
                          ? v1::NORMAL_WEIGHTING_AREA
                          : v1::NORMAL_WEIGHTING_UNIFORM);
  options.set_point_reduction(to_proto(poisson.point_reduction));
  options.set_point_cell_voxels(poisson.point_cell_voxels);
  options.set_point_cluster_size(poisson.point_cluster_size);
  options.set_max_points(poisson.max_points);
  options.set_split_points(poisson.split_points);
  options.set_prune_strands(poisson.prune_strands);
  options.set_smoothing_iterations(poisson.smoothing.iterations);
  options.set_smoothing_pass_band(poisson.smoothing.pass_band);
  if (poisson.max_edge_mm > 0) options.set_max_edge_mm(poisson.max_edge_mm);
  if (poisson.max_distance_mm > 0) options.set_max_distance_mm(poisson.max_distance_mm);
  options.set_adapt_to_thickness(poisson.adapt_to_thickness);
  options.set_poisson_min_thickness_voxels(poisson.min_thickness_voxels);
  for (const auto& named : params.label_names) {
    auto* entry = options.add_label_names();
    entry->set_label(named.label);
    entry->set_name(named.name);
    if (named.colour) {
      for (uint8_t c : *named.colour) entry->add_colour_rgb(c);
    }
  }
  for (const auto& sizing : poisson.label_sizing) {
    auto* entry = options.add_label_sizing();
    entry->set_label(sizing.label);
    entry->set_max_edge_mm(sizing.max_edge_mm);
    entry->set_max_distance_mm(sizing.max_distance_mm);
  }
  const GuardOptions& guard = params.guard;
  options.set_volume_tolerance_percent(guard.volume_percent);
  options.set_small_volume_tolerance_percent(guard.small_volume_percent);
  options.set_hausdorff_tolerance_mm(guard.hausdorff_mm);
  options.set_fall_back(guard.fall_back);
  options.set_strict(guard.strict);
  options.set_mesh_on_drawn_grid(params.mesh_on_drawn_grid);

  for (auto format : params.formats)
    options.add_formats(std::string(surface::surface_format_name(format)));
  if (params.dicom_surfaces) options.add_formats(std::string(kDicomSurfaceFormat));
  if (params.volume != VolumeMethod::kNone) {
    options.set_volume(params.volume == VolumeMethod::kMixed        ? v1::VOLUME_METHOD_MIXED
                       : params.volume == VolumeMethod::kHex        ? v1::VOLUME_METHOD_HEX
                       : params.volume == VolumeMethod::kConforming ? v1::VOLUME_METHOD_CONFORMING
                                                                    : v1::VOLUME_METHOD_TETGEN);
    options.set_hex_size_mm(params.hex_size_mm);
    options.set_hex_interior_size_mm(params.hex_interior_size_mm);
    options.set_conforming_max_interface_faces(params.conforming_max_interface_faces);
    for (auto format : params.volume_formats)
      options.add_formats(std::string(volume_mesh::volume_format_name(format)));
  } else {
    options.set_volume(v1::VOLUME_METHOD_NONE);
  }
  for (auto format : params.scene_formats)
    options.add_formats(std::string(scene_format_name(format)));
  options.set_coordinates(params.frame == CoordinateFrame::kRas ? v1::COORDINATE_FRAME_RAS
                                                                : v1::COORDINATE_FRAME_LPS);
  options.set_overlapping_segments(params.limits.separate_overlapping
                                       ? v1::OVERLAPPING_SEGMENTS_SEPARATE
                                       : v1::OVERLAPPING_SEGMENTS_REFUSE);
  options.set_tet_radius_edge(params.tetgen.radius_edge_ratio);
  options.set_tet_min_dihedral_deg(params.tetgen.min_dihedral_deg);
  options.set_tet_max_volume_mm3(params.tetgen.max_volume_mm3);
  options.set_tet_keep_boundary(params.tetgen.keep_boundary);
  options.set_tet_max_dihedral_deg(params.tetgen.max_dihedral_deg);
  options.set_tet_improve_quality(params.improve.target_quality);
  options.set_max_voxels(params.limits.max_voxels);
  return options;
}

absl::StatusOr<MeshParams> params_from_options(const v1::MeshOptions& options) {
  MeshParams params;
  LABELMESH_RETURN_IF_ERROR(read_label_names(options, params.label_names));
  if (options.labels_size() > kMaxLabels)
    return absl::InvalidArgumentError(
        cat("labels: ", options.labels_size(), " entries; at most ", kMaxLabels));
  // Each label once, in the order first given.
  for (int32_t label : options.labels()) {
    if (std::find(params.labels.begin(), params.labels.end(), label) == params.labels.end())
      params.labels.push_back(label);
  }
  switch (options.surface()) {
    case v1::SURFACE_METHOD_MARCHING_CUBES:
      params.surface = SurfaceMethod::kMarchingCubes;
      break;
    case v1::SURFACE_METHOD_REPAIRED:
      params.surface = SurfaceMethod::kRepaired;
      break;
    case v1::SURFACE_METHOD_POISSON:
      params.surface = SurfaceMethod::kPoisson;
      break;
    case v1::SURFACE_METHOD_UNSPECIFIED:
    case v1::SURFACE_METHOD_NET:
      params.surface = SurfaceMethod::kNet;
      break;
    default:
      return absl::InvalidArgumentError("surface: unknown surface method");
  }
  LABELMESH_RETURN_IF_ERROR(read_poisson_options(options, params.poisson));
  LABELMESH_RETURN_IF_ERROR(read_guard_options(options, params.guard));
  LABELMESH_RETURN_IF_ERROR(read_volume_options(options, params));
  // Per-label tetrahedra and hexahedra want surfaces sized for elements, not
  // one node per voxel face: unless asked otherwise they mesh Poisson's.
  const bool element_sized = params.volume == VolumeMethod::kTetgen ||
                             params.volume == VolumeMethod::kMixed ||
                             params.volume == VolumeMethod::kHex;
  if (options.surface() == v1::SURFACE_METHOD_UNSPECIFIED && element_sized)
    params.surface = SurfaceMethod::kPoisson;
  if (options.formats_size() > kMaxFormatEntries)
    return absl::InvalidArgumentError(
        cat("formats: ", options.formats_size(), " entries; at most ", kMaxFormatEntries));
  if (!options.formats().empty()) {
    // One list for both kinds: each name is either a surface or a volume
    // format, kept once in the order first given.
    params.formats.clear();
    params.dicom_surfaces = false;
    std::vector<volume_mesh::VolumeFormat> volume_formats;
    std::vector<SceneFormat> scene_formats;
    auto add_once = [](auto& list, auto format) {
      if (std::find(list.begin(), list.end(), format) == list.end()) list.push_back(format);
    };
    for (const auto& name : options.formats()) {
      if (auto format = surface::surface_format_from_name(name)) {
        add_once(params.formats, *format);
      } else if (auto volume_format = volume_mesh::volume_format_from_name(name)) {
        add_once(volume_formats, *volume_format);
      } else if (auto scene_format = scene_format_from_name(name)) {
        add_once(scene_formats, *scene_format);
      } else if (name == kDicomSurfaceFormat) {
        params.dicom_surfaces = true;
      } else {
        return absl::InvalidArgumentError(cat(
            "formats: '", name,
            "' is not one of stl, ply, obj, off, vtp, dcm (surfaces), vtm, vti, mha (scene), vtu, "
            "msh, mesh, inp, node, xdmf (volumes)"));
      }
    }
    if (!volume_formats.empty()) {
      if (params.volume == VolumeMethod::kNone) {
        return absl::InvalidArgumentError(
            "formats: a volume format was asked for without a volume method (volume: tet)");
      }
      params.volume_formats = std::move(volume_formats);
    }
    if ((params.volume == VolumeMethod::kMixed || params.volume == VolumeMethod::kHex) &&
        std::count_if(params.volume_formats.begin(), params.volume_formats.end(),
                      [](volume_mesh::VolumeFormat format) {
                        return format == volume_mesh::VolumeFormat::kTetgen ||
                               format == volume_mesh::VolumeFormat::kXdmf;
                      }) > 0) {
      return absl::InvalidArgumentError(
          "formats: node (TetGen) and xdmf hold tetrahedra only here; a mixed mesh goes to vtu, "
          "msh, mesh or inp");
    }
    params.scene_formats = std::move(scene_formats);
  }
  switch (options.overlapping_segments()) {
    case v1::OVERLAPPING_SEGMENTS_UNSPECIFIED:
    case v1::OVERLAPPING_SEGMENTS_REFUSE:
      params.limits.separate_overlapping = false;
      break;
    case v1::OVERLAPPING_SEGMENTS_SEPARATE:
      params.limits.separate_overlapping = true;
      break;
    default:
      return absl::InvalidArgumentError("overlapping_segments: unknown choice");
  }
  switch (options.coordinates()) {
    case v1::COORDINATE_FRAME_UNSPECIFIED:
    case v1::COORDINATE_FRAME_LPS:
      params.frame = CoordinateFrame::kLps;
      break;
    case v1::COORDINATE_FRAME_RAS:
      params.frame = CoordinateFrame::kRas;
      break;
    default:
      return absl::InvalidArgumentError("coordinates: unknown coordinate frame");
  }
  if (options.max_voxels() > 0) params.limits.max_voxels = options.max_voxels();
  return params;
}

absl::Status check_sizing_for_grid(const PoissonOptions& poisson,
                                   const volume::ImageGeometry& geometry) {
  const double voxel = std::cbrt(geometry.voxel_volume());
  auto at_least = [&](std::string_view field, double mm, double finest_voxels) {
    // A hair of slack: half of a 3 mm voxel is 1.5 mm, not a rounding below.
    if (mm <= 0 || mm >= finest_voxels * voxel * (1 - 1e-9)) return absl::OkStatus();
    return absl::InvalidArgumentError(cat(field, ": ", mm, " mm is finer than ", finest_voxels,
                                          " voxel (", finest_voxels * voxel,
                                          " mm on this grid), which the voxels cannot tell apart"));
  };
  LABELMESH_RETURN_IF_ERROR(at_least("max_edge_mm", poisson.max_edge_mm, kFinestEdgeVoxels));
  LABELMESH_RETURN_IF_ERROR(
      at_least("max_distance_mm", poisson.max_distance_mm, kFinestDistanceVoxels));
  for (const auto& sizing : poisson.label_sizing) {
    const std::string field = cat("label_sizing: label ", sizing.label);
    LABELMESH_RETURN_IF_ERROR(at_least(field, sizing.max_edge_mm, kFinestEdgeVoxels));
    LABELMESH_RETURN_IF_ERROR(at_least(field, sizing.max_distance_mm, kFinestDistanceVoxels));
  }
  return absl::OkStatus();
}

}  // namespace labelmesh
