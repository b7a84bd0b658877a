// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/pipeline.h"

#include "core/job/job_options.h"

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <limits>
#include <thread>

#include "absl/synchronization/mutex.h"
#include "core/dicom/dicom_source.h"
#include "core/digest/sha256.h"
#include "core/header/volume_header.h"
#include "core/pipeline/label_conforming_mesh.h"
#include "core/pipeline/label_net_surfaces.h"
#include "core/pipeline/label_queue.h"
#include "core/pipeline/label_surfaces.h"
#include "core/pipeline/labels_crossing.h"
#include "core/pipeline/volume_layers.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/voxel_fidelity.h"
#include "core/util/exception_status.h"
#include "core/util/side_by_side.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/drawn_grid.h"
#include "core/volume/label_table.h"
#include "core/volume/read_label_volume.h"
#include "core/volume/repeated_planes.h"
#include "core/volume/touching_labels.h"

namespace labelmesh {
namespace {

// The input's format, placement, label counts and repeated planes.
VolumeSummary summary_of(const volume::LabelVolume& volume) {
  VolumeSummary summary;
  summary.format = volume.format;
  summary.file_voxel_type = volume.file_voxel_type;
  summary.geometry = volume.geometry;
  summary.statistics = volume::compute_label_statistics(volume);
  summary.repeated_planes = volume::find_repeated_planes(volume, summary.statistics);
  summary.descriptions = volume.descriptions;
  return summary;
}

// The same for a volume whose overlapping segments lie in layers: the
// first layer's placement, every layer's labels.
VolumeSummary summary_of(const std::vector<volume::LabelVolume>& layers) {
  VolumeSummary summary = summary_of(layers.front());
  if (layers.size() > 1) summary.statistics = layered_statistics(layers);
  summary.layers = static_cast<uint32_t>(layers.size());
  return summary;
}

// The labels to mesh: those asked for (each must be present), or all.
absl::StatusOr<std::vector<int32_t>> choose_labels(const std::string& path,
                                                   const volume::VolumeStatistics& statistics,
                                                   const std::vector<int32_t>& asked) {
  std::vector<int32_t> labels;
  if (asked.empty()) {
    for (const auto& label : statistics.labels) labels.push_back(label.label);
    if (labels.empty()) {
      return absl::FailedPreconditionError(
          cat(path, ": the volume holds only background (label 0); nothing to mesh"));
    }
    return labels;
  }
  for (int32_t label : asked) {
    if (label == 0)
      return absl::InvalidArgumentError("labels: 0 is the background and has no surface");
    if (statistics.find(label) == nullptr) {
      return absl::InvalidArgumentError(cat("labels: ", path, " has no voxel with label ", label));
    }
    if (std::find(labels.begin(), labels.end(), label) == labels.end()) labels.push_back(label);
  }
  return labels;
}

// One warning per label delivered outside its tolerance or not at all (its
// stages failed, or nothing was left once small components and strands were
// dropped).
std::vector<LabelWarning> collect_warnings(const std::vector<SurfaceResult>& surfaces,
                                           const MeshParams& params) {
  std::vector<LabelWarning> warnings;
  for (const auto& s : surfaces) {
    if (s.stage == "marching_cubes") continue;
    if (s.error) {
      warnings.push_back({s.label, cat("not delivered: ", *s.error)});
      continue;
    }
    if (s.components && s.components->kept == 0) {
      warnings.push_back(
          {s.label, cat("too small to mesh: no component of ", params.poisson.min_component_voxels,
                        " voxels or more (min_component_voxels) once one-voxel strands are "
                        "pruned; ",
                        s.components->dropped, " smaller component(s), ",
                        s.components->pruned_voxels, " voxels in strands")});
      continue;
    }
    if (!s.is_output || !s.fidelity) continue;
    const auto& f = *s.fidelity;
    const auto& a = f.attempts[f.delivered];
    if (!f.within_tolerance() && a.voxels) {
      const auto& v = *a.voxels;
      warnings.push_back(
          {s.label, cat("outside tolerance: ", method_name(a.method), " surface, volume ",
                        format_fixed(100 * v.volume_change, 1), " % of the voxels' (tolerance ",
                        format_fixed(100 * f.tolerance.volume_fraction, 1), " %), ",
                        v.misclassified, " voxel centres on the wrong side (",
                        format_fixed(100 * v.misclassified_fraction(), 2), " % of ",
                        v.boundary_voxels, " boundary voxels; tolerance ",
                        format_fixed(100 * f.tolerance.misclassified_fraction, 1), " %), farthest ",
                        format_fixed(v.farthest_misclassified_voxels, 2), " voxel (tolerance ",
                        format_fixed(f.tolerance.misclassified_reach_voxels, 2), "), Hausdorff ",
                        format_fixed(v.hausdorff_voxels, 2), " voxel (tolerance ",
                        format_fixed(f.tolerance.hausdorff_voxels, 2), ")")});
    } else if (!f.within_tolerance()) {
      warnings.push_back(
          {s.label, cat("outside tolerance: ", method_name(a.method), " surface, volume ",
                        format_fixed(100 * a.volume_change, 1), " % (tolerance ",
                        format_fixed(100 * f.tolerance.volume_fraction, 1), " %), Hausdorff ",
                        format_fixed(a.hausdorff_mm, 2), " mm (tolerance ",
                        format_fixed(f.tolerance.hausdorff_mm, 2), " mm)")});
    }
  }
  return warnings;
}

// Labels with at least this many voxels are meshed one at a time (LabelQueue).
constexpr uint64_t kLargeLabelVoxels = 100'000;

// Hands the heap's free pages back to the system, after each large label.
// glibc keeps one arena per thread, and what a large label freed in one
// thread's arena is not reused by the next large label on another thread:
// without this the brain's peak resident memory was two large labels' worth
// although only one ran at a time. Small labels free too little to matter.
void release_free_memory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

// How many labels are meshed at once: the params' budget, else every core.
unsigned label_threads(const MeshParams& params, size_t labels) {
  unsigned threads = params.threads > 0 ? params.threads : std::thread::hardware_concurrency();
  return static_cast<unsigned>(std::clamp<size_t>(threads, 1, std::max<size_t>(labels, 1)));
}

// The quality surfaces of every label in `labels`, several labels at once
// (label_threads). Each label's surfaces and stage times are kept apart and
// joined in label order, so the result does not depend on the thread count.
// A label whose stages fail gets that error and the others go on; a stop, a
// bad option, or a failure of a label asked for by name ends the run.
// Each label's delivery tolerance, in the order of `labels`.
std::vector<SurfaceTolerance> label_tolerances(const volume::ImageGeometry& geometry,
                                               const VolumeSummary& input,
                                               const std::vector<int32_t>& labels,
                                               const GuardOptions& guard) {
  std::array<double, 3> drawn_spacing;
  for (int axis = 0; axis < 3; ++axis)
    drawn_spacing[axis] = geometry.spacing[axis] * input.repeated_planes[axis];
  std::vector<SurfaceTolerance> tolerances;
  for (int32_t label : labels) {
    tolerances.push_back(tolerance_for(input.statistics.find(label)->voxels, drawn_spacing,
                                       guard.volume_percent, guard.small_volume_percent,
                                       guard.hausdorff_mm));
  }
  return tolerances;
}

absl::Status add_every_label_surface(const std::vector<volume::LabelVolume>& layers,
                                     const std::vector<size_t>& layer_of,
                                     const VolumeSummary& input, const std::vector<int32_t>& labels,
                                     const MeshParams& params, const RunContext& context,
                                     std::vector<SurfaceResult>& surfaces,
                                     std::vector<StageTiming>& stages) {
  // The shared nets are built once, before any label.
  std::optional<LabelNets> nets;
  if (params.surface == SurfaceMethod::kNet) {
    LABELMESH_ASSIGN_OR_RETURN(auto built,
                               build_label_nets(layers, layer_of, labels, params, context, stages));
    nets = std::move(built);
  }
  const auto tolerances = label_tolerances(layers.front().geometry, input, labels, params.guard);
  const size_t count = labels.size();
  std::vector<std::vector<SurfaceResult>> label_surfaces(count);
  std::vector<std::vector<StageTiming>> label_stages(count);
  std::vector<absl::Status> label_status(count);
  // Each label's stages report which label they work on, and how many
  // labels are done by then.
  std::vector<LabelInProgress> in_progress(count);
  std::atomic<uint32_t> labels_done{0};
  // Progress callbacks expect one caller at a time.
  absl::Mutex progress_mutex;
  RunContext shared = context;
  if (context.progress) {
    shared.progress = [&](const ProgressUpdate& update) {
      absl::MutexLock lock(&progress_mutex);
      if (update.label == nullptr) return context.progress(update);
      LabelInProgress now = *update.label;
      now.done = labels_done.load();
      context.progress({update.stage, update.fraction, &now});
    };
  }
  for (size_t i = 0; i < count; ++i) {
    in_progress[i].label = labels[i];
    in_progress[i].index = static_cast<uint32_t>(i + 1);
    in_progress[i].count = static_cast<uint32_t>(count);
    for (const auto& description : input.descriptions)
      if (description.label == labels[i]) in_progress[i].name = description.name;
  }
  std::vector<bool> large(count);
  for (size_t i = 0; i < count; ++i)
    large[i] = input.statistics.find(labels[i])->voxels >= kLargeLabelVoxels;
  LabelQueue queue(large);
  auto work = [&] {
    while (const auto taken = queue.take()) {
      const size_t i = *taken;
      const auto* statistics = input.statistics.find(labels[i]);
      const SurfaceTolerance& tolerance = tolerances[i];
      RunContext label_context = shared;
      label_context.label = &in_progress[i];
      absl::Status status;
      try {
        status = nets ? add_net_label_surface(*nets, layer_of[i], i, layers[layer_of[i]],
                                              *statistics, tolerance, params, label_context,
                                              label_surfaces[i], label_stages[i])
                      : add_label_surfaces(layers[layer_of[i]], *statistics, params, tolerance,
                                           label_context, label_surfaces[i], label_stages[i]);
      } catch (const std::bad_alloc&) {
        status = absl::ResourceExhaustedError(cat("label ", labels[i], ": out of memory"));
      }
      const bool label_error = !status.ok() && status.code() != absl::StatusCode::kCancelled &&
                               status.code() != absl::StatusCode::kInvalidArgument &&
                               params.labels.empty();
      if (label_error) {
        SurfaceResult failed;
        failed.label = labels[i];
        failed.stage = params.surface == SurfaceMethod::kNet       ? "net"
                       : params.surface == SurfaceMethod::kPoisson ? "poisson"
                                                                   : "repaired";
        failed.error = std::string(status.message());
        label_surfaces[i] = {};
        label_surfaces[i].push_back(std::move(failed));
        status = absl::OkStatus();
      }
      label_status[i] = status;
      ++labels_done;
      if (!status.ok()) queue.end();
      queue.done(i);
      if (large[i]) release_free_memory();
    }
  };
  const unsigned threads = label_threads(params, count);
  std::vector<std::thread> helpers;
  for (unsigned t = 1; t < threads; ++t) helpers.emplace_back(work);
  work();
  for (auto& helper : helpers) helper.join();
  for (size_t i = 0; i < count; ++i) {
    if (!label_status[i].ok()) return label_status[i];
    for (auto& surface : label_surfaces[i]) surfaces.push_back(std::move(surface));
    for (const auto& stage : label_stages[i]) add_stage_time(stages, stage.name, stage.seconds);
  }
  return absl::OkStatus();
}

// The layer each of `labels` lives in.
std::vector<size_t> layer_of_labels(const std::vector<volume::LabelVolume>& layers,
                                    const std::vector<int32_t>& labels) {
  std::vector<size_t> layer_of(labels.size(), 0);
  if (layers.size() == 1) return layer_of;
  for (size_t layer = 0; layer < layers.size(); ++layer) {
    const auto statistics = volume::compute_label_statistics(layers[layer]);
    for (size_t i = 0; i < labels.size(); ++i)
      if (statistics.find(labels[i]) != nullptr) layer_of[i] = layer;
  }
  return layer_of;
}

// Each label with its layer.
std::vector<std::pair<int32_t, size_t>> label_layers(const std::vector<int32_t>& labels,
                                                     const std::vector<size_t>& layer_of) {
  std::vector<std::pair<int32_t, size_t>> pairs;
  for (size_t i = 0; i < labels.size(); ++i) pairs.push_back({labels[i], layer_of[i]});
  return pairs;
}

// Marching Cubes of each label from its own layer, in the order of `labels`.
absl::StatusOr<std::vector<surface::LabelSurface>> extract_layer_surfaces(
    const std::vector<volume::LabelVolume>& layers, const std::vector<size_t>& layer_of,
    const volume::VolumeStatistics& statistics, const std::vector<int32_t>& labels,
    const RunContext& context) {
  if (layers.size() == 1)
    return surface::extract_surfaces(layers.front(), statistics, labels, context);
  std::vector<surface::LabelSurface> all(labels.size());
  for (size_t layer = 0; layer < layers.size(); ++layer) {
    std::vector<int32_t> here;
    std::vector<size_t> at;
    for (size_t i = 0; i < labels.size(); ++i) {
      if (layer_of[i] != layer) continue;
      here.push_back(labels[i]);
      at.push_back(i);
    }
    if (here.empty()) continue;
    LABELMESH_ASSIGN_OR_RETURN(auto extracted,
                               surface::extract_surfaces(layers[layer], statistics, here, context));
    for (size_t k = 0; k < at.size(); ++k) all[at[k]] = std::move(extracted[k]);
  }
  return all;
}

// Mixed elements for each label's output surface.
absl::Status add_mixed_mesh(const MeshParams& params, const volume::ImageGeometry& geometry,
                            const RunContext& context, MeshResult& result) {
  std::vector<LabelBoundary> boundaries;
  for (const auto& surface : result.surfaces) {
    if (surface.is_output)
      boundaries.push_back({surface.label, &surface.mesh, surface.self_intersections});
  }
  mixed_mesh::MixedParams mixed;
  mixed.core.cell_mm = params.hex_size_mm > 0 ? params.hex_size_mm : 3 * voxel_size_mm(geometry);
  mixed.core.threads = label_threads(params, std::numeric_limits<size_t>::max());
  mixed.hexahedra_only = params.volume == VolumeMethod::kHex;
  mixed.octree.interior_mm = params.hex_interior_size_mm;
  mixed.tetgen = params.tetgen;
  // Points TetGen added on the pyramids' triangles would leave their squares
  // facing split triangles: the layer's boundaries are always kept.
  mixed.tetgen.keep_boundary = true;
  StageTimer timer(result.stages, "mixed_mesh");
  LABELMESH_ASSIGN_OR_RETURN(auto meshes, mesh_labels_mixed(boundaries, mixed, context));
  for (const auto& left_out : meshes.labels_left_out)
    result.warnings.push_back({left_out.label, cat("no volume mesh: ", left_out.reason)});
  result.mixed = std::move(meshes);
  return absl::OkStatus();
}

// TetGen on each label's output surface, then the improvement pass.
absl::Status add_volume_mesh(const MeshParams& params, const volume::ImageGeometry& geometry,
                             const RunContext& context, MeshResult& result) {
  std::vector<LabelBoundary> boundaries;
  for (const auto& surface : result.surfaces) {
    if (surface.is_output)
      boundaries.push_back({surface.label, &surface.mesh, surface.self_intersections});
  }
  absl::StatusOr<VolumeResult> tets;
  {
    StageTimer timer(result.stages, "tetgen");
    context.report("tetgen", 0);
    tets = tetrahedralize_labels(boundaries, params.tetgen, context);
  }
  if (!tets.ok()) return tets.status();
  {
    StageTimer timer(result.stages, "tet_improve");
    context.report("tet_improve", 0);
    const auto improve = improve_params_for(params, geometry);
    LABELMESH_RETURN_IF_ERROR(improve_volume(*tets, improve, context));
  }
  result.volume = std::move(*tets);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<VolumeSummary> summarise_volume(const std::string& path,
                                               const volume::ReadLimits& limits,
                                               const RunContext& context) {
  try {
    LABELMESH_ASSIGN_OR_RETURN(auto volume, volume::read_label_volume(path, limits, context));
    return summary_of(volume_layers(volume));
  } catch (...) {
    return current_exception_status(path);
  }
}

volume_mesh::ImproveParams improve_params_for(const MeshParams& params,
                                              const volume::ImageGeometry& geometry) {
  volume_mesh::ImproveParams improve = params.improve;
  improve.max_volume_mm3 = params.tetgen.max_volume_mm3;
  // Peeling may move a Poisson surface as far as its meshing may; other
  // surfaces have no such tolerance and stay as they are.
  if (params.surface == SurfaceMethod::kPoisson) {
    improve.max_peel_depth_mm = params.poisson.max_distance_voxels * voxel_size_mm(geometry);
  }
  return improve;
}

namespace {

absl::StatusOr<MeshResult> run_on_volume(const std::string& path,
                                         absl::StatusOr<volume::LabelVolume> volume,
                                         const MeshParams& params, const RunContext& context,
                                         MeshResult result);

absl::StatusOr<MeshResult> run_stages(const std::string& path, const MeshParams& params,
                                      const RunContext& context) {
  // DICOM surfaces need a DICOM SEG's patient and study: refused before
  // the volume is read.
  std::optional<dicom::DicomSource> dicom;
  if (params.dicom_surfaces) {
    const auto format = volume::format_of_file(path);
    if (format && *format != volume::ImageFormat::kDicomSeg) {
      return absl::InvalidArgumentError(
          cat(path,
              ": formats: dcm (DICOM Encapsulated STL) needs a DICOM SEG input to take "
              "the patient, study and frame of reference from; this file is ",
              volume::format_name(*format)));
    }
  }
  MeshResult result;
  absl::StatusOr<volume::LabelVolume> volume;
  absl::StatusOr<std::string> digest;
  {
    StageTimer timer(result.stages, "read");
    context.report("read", 0);
    volume = volume::read_label_volume(path, params.limits, context);
    if (volume.ok()) digest = digest::sha256_file(path);
  }
  if (!volume.ok()) return volume.status();
  if (params.dicom_surfaces) {
    LABELMESH_ASSIGN_OR_RETURN(auto source, dicom::read_dicom_source(path));
    dicom = std::move(source);
  }
  auto meshed = run_on_volume(path, std::move(volume), params, context, std::move(result));
  if (meshed.ok()) {
    meshed->input.file_name = std::filesystem::path(path).filename().string();
    if (digest.ok()) meshed->input.sha256 = *digest;
    meshed->input.dicom = std::move(dicom);
  }
  return meshed;
}

// Under --strict, any warning (a label outside tolerance, a surface or a
// volume mesh not delivered, a surface made apart entering another label's)
// fails the run.
absl::Status refuse_warnings_if_strict(const std::string& path, const MeshResult& result,
                                       const MeshParams& params) {
  if (!params.guard.strict || result.warnings.empty()) return absl::OkStatus();
  std::vector<int32_t> warned;
  for (const auto& w : result.warnings) warned.push_back(w.label);
  std::sort(warned.begin(), warned.end());
  warned.erase(std::unique(warned.begin(), warned.end()), warned.end());
  const auto& first = result.warnings.front();
  return absl::FailedPreconditionError(
      cat(path, ": strict: ", warned.size(),
          " label(s) delivered outside tolerance, not at all, or into another label's surface; "
          "first, label ",
          first.label, ": ", first.reason));
}

// The stages after reading; `path` names the input in messages.
absl::StatusOr<MeshResult> run_on_volume(const std::string& path,
                                         absl::StatusOr<volume::LabelVolume> volume,
                                         const MeshParams& params, const RunContext& context,
                                         MeshResult result) {
  if (auto s = check_sizing_for_grid(params.poisson, volume->geometry); !s.ok())
    return absl::InvalidArgumentError(cat(path, ": ", std::string(s.message())));
  // The scene formats other than vtm write the label volume as read.
  const bool writes_label_image =
      std::any_of(params.scene_formats.begin(), params.scene_formats.end(),
                  [](SceneFormat f) { return f != SceneFormat::kVtm; });
  // Where the labels are meshed on the grid they were drawn on: the file's
  // grid, and its volume when a scene format writes it.
  std::optional<volume::ImageGeometry> file_geometry;
  std::optional<volume::LabelVolume> file_volume;
  if (params.mesh_on_drawn_grid) {
    StageTimer timer(result.stages, "drawn_grid");
    const auto grid = volume::find_drawn_grid(*volume);
    if (grid.resampled()) {
      auto drawn = volume::resample_to_drawn_grid(*volume, grid);
      if (!drawn.ok()) {
        return absl::Status(drawn.status().code(),
                            cat(path, ": ", std::string(drawn.status().message())));
      }
      file_geometry = volume->geometry;
      if (writes_label_image) file_volume = std::move(*volume);
      volume = std::move(*drawn);
      if (auto s = check_sizing_for_grid(params.poisson, volume->geometry); !s.ok()) {
        return absl::InvalidArgumentError(
            cat(path, ": ", std::string(s.message()),
                " (the labels were drawn on this coarser grid; --file-grid meshes on the "
                "file's)"));
      }
    }
  }
  const std::vector<volume::LabelVolume> layers = volume_layers(*volume);
  {
    StageTimer timer(result.stages, "label_statistics");
    result.input = summary_of(layers);
    result.input.file_geometry = file_geometry;
    volume::apply_label_table(params.label_names, result.input.descriptions);
  }
  LABELMESH_ASSIGN_OR_RETURN(auto labels,
                             choose_labels(path, result.input.statistics, params.labels));
  auto layer_of = layer_of_labels(layers, labels);
  // The label volume as read, for the scene formats that write it.
  const auto keep_label_image = [&] {
    if (writes_label_image) {
      result.label_image = std::make_shared<const volume::LabelVolume>(
          std::move(file_volume ? *file_volume : *volume));
    }
  };
  if (params.volume == VolumeMethod::kConforming) {
    if (layers.size() > 1) {
      return absl::FailedPreconditionError(
          cat(path, ": its segments overlap (", layers.size(),
              " layers); one conforming mesh gives each point one label, so mesh overlapping "
              "segments with --volume tet"));
    }
    LABELMESH_RETURN_IF_ERROR(add_conforming_mesh(*volume, labels, params, context, result));
    LABELMESH_RETURN_IF_ERROR(refuse_warnings_if_strict(path, result, params));
    keep_label_image();
    return result;
  }

  absl::StatusOr<std::vector<surface::LabelSurface>> surfaces;
  {
    StageTimer timer(result.stages, "marching_cubes");
    context.report("marching_cubes", 0);
    surfaces = extract_layer_surfaces(layers, layer_of, result.input.statistics, labels, context);
  }
  if (!surfaces.ok()) return surfaces.status();
  // The Marching Cubes figures. When quality surfaces follow, the Marching
  // Cubes meshes are only measured, on a second thread while the quality
  // surfaces' first stages (components, repair) keep one core busy, and then
  // dropped.
  const bool quality = params.surface != SurfaceMethod::kMarchingCubes;
  const bool tetrahedra = params.volume == VolumeMethod::kTetgen;
  std::vector<StageTiming> statistics_stage;
  auto measure_marching_cubes = [&] {
    StageTimer timer(statistics_stage, "surface_statistics");
    for (auto& extracted : *surfaces) {
      // The caller checks for the stop once both threads are done.
      if (context.stop_requested()) return;
      SurfaceResult surface;
      surface.label = extracted.label;
      surface.stage = "marching_cubes";
      surface.is_output = !quality;
      surface.statistics = surface::compute_surface_statistics(extracted.mesh);
      surface.axis_aligned_share =
          surface::axis_aligned_share(extracted.mesh, layers.front().geometry);
      if (!quality) surface.mesh = std::move(extracted.mesh);
      extracted.mesh = {};
      result.surfaces.push_back(std::move(surface));
    }
  };
  // Listed where it runs first, whatever finishes first.
  result.stages.push_back({"surface_statistics", 0});
  std::vector<SurfaceResult> quality_surfaces;
  absl::Status quality_status;
  if (!quality) {
    measure_marching_cubes();
  } else {
    side_by_side(measure_marching_cubes, [&] {
      quality_status = add_every_label_surface(layers, layer_of, result.input, labels, params,
                                               context, quality_surfaces, result.stages);
    });
  }
  add_stage_time(result.stages, "surface_statistics", statistics_stage.front().seconds);
  if (!quality_status.ok()) return quality_status;
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  if (quality && std::none_of(quality_surfaces.begin(), quality_surfaces.end(),
                              [](const SurfaceResult& s) { return s.is_output; })) {
    return absl::FailedPreconditionError(
        cat(path,
            ": no label left a surface: every label's components are smaller than "
            "min-component-voxels (",
            params.poisson.min_component_voxels, ") or its stages failed; nothing to mesh"));
  }
  for (auto& surface : quality_surfaces) result.surfaces.push_back(std::move(surface));
  result.warnings = collect_warnings(result.surfaces, params);
  // Labels made apart from the shared net may enter their neighbours'
  // surfaces; per-label methods asked for by name are made apart anyway,
  // and so are segments of different layers (they overlap in the voxels).
  if (params.surface == SurfaceMethod::kNet)
    for (const auto& c : labels_crossing(result.surfaces, label_layers(labels, layer_of)))
      result.warnings.push_back(
          {c.label, cat("surface crosses label ", c.other, "'s: ", c.triangle_pairs,
                        " pair(s) of triangles pass through each other (made apart from the "
                        "shared surface net)")});
  // Refused before the volume meshes, which would take long for nothing.
  LABELMESH_RETURN_IF_ERROR(refuse_warnings_if_strict(path, result, params));

  if (tetrahedra || params.volume == VolumeMethod::kMixed || params.volume == VolumeMethod::kHex) {
    // Labels are meshed one by one: where they touch, their meshes overlap.
    for (size_t layer = 0; layer < layers.size(); ++layer) {
      auto touching = volume::touching_labels(layers[layer], labels);
      result.touching_labels.insert(result.touching_labels.end(), touching.begin(), touching.end());
    }
  }
  if (tetrahedra) {
    LABELMESH_RETURN_IF_ERROR(add_volume_mesh(params, volume->geometry, context, result));
  }
  if (params.volume == VolumeMethod::kMixed || params.volume == VolumeMethod::kHex) {
    LABELMESH_RETURN_IF_ERROR(add_mixed_mesh(params, volume->geometry, context, result));
  }
  LABELMESH_RETURN_IF_ERROR(refuse_warnings_if_strict(path, result, params));
  keep_label_image();
  return result;
}

}  // namespace

absl::StatusOr<MeshResult> run_pipeline(const std::string& path, const MeshParams& params,
                                        const RunContext& context) {
  try {
    return run_stages(path, params, context);
  } catch (...) {
    return current_exception_status("pipeline");
  }
}

absl::StatusOr<MeshResult> run_pipeline_on_volume(volume::LabelVolume volume,
                                                  const MeshParams& params,
                                                  const RunContext& context) {
  try {
    return run_on_volume("the volume", std::move(volume), params, context, MeshResult{});
  } catch (...) {
    return current_exception_status("pipeline");
  }
}

}  // namespace labelmesh
