#include "core/quality_surfaces.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>

#include "core/side_by_side.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/smooth_surface.h"
#include "core/surface/surface_checks.h"
#include "core/surface/vertex_normals.h"
#include "core/text.h"
#include "core/volume/label_components.h"

namespace labelmesh {
namespace {

using surface::TriangleMesh;

struct Pieces {
  ComponentCounts counts;
  // Marching Cubes surface of each kept component.
  std::vector<TriangleMesh> meshes;
};

absl::StatusOr<Pieces> kept_component_surfaces(const volume::LabelVolume& volume,
                                               const volume::LabelStatistics& label,
                                               const PoissonOptions& options,
                                               const RunContext& context) {
  volume::ComponentOptions component_options;
  component_options.prune_strands = options.prune_strands;
  // Pockets of background inside the label too small to keep as islands are
  // segmentation noise too: Poisson closes them, and the distance check would
  // measure them (a 1-voxel hole 10 mm deep in the liver file's label 127).
  component_options.fill_cavities_below = options.min_component_voxels;
  auto components = volume::find_label_components(volume, label, component_options, context);
  if (!components.ok()) return components.status();
  const uint64_t min_voxels = options.min_component_voxels;
  Pieces pieces;
  pieces.counts.pruned_voxels = components->pruned_voxels;
  pieces.counts.filled_cavities = components->filled_cavities;
  pieces.counts.filled_voxels = components->filled_voxels;
  std::vector<int32_t> kept;
  for (const auto& component : components->components) {
    if (component.voxels >= min_voxels) {
      kept.push_back(component.id);
    } else {
      ++pieces.counts.dropped;
      pieces.counts.dropped_voxels += component.voxels;
    }
  }
  pieces.counts.kept = static_cast<uint32_t>(kept.size());
  if (kept.empty()) return pieces;
  auto meshes = surface::extract_component_surfaces(*components, kept, volume.geometry, context);
  if (!meshes.ok()) return meshes.status();
  pieces.meshes = std::move(*meshes);
  return pieces;
}

// Progress as a fraction of the label's points, which is roughly the work.
class PieceProgress {
 public:
  PieceProgress(const RunContext& context, std::string stage,
                const std::vector<TriangleMesh>& pieces)
      : context_(context), stage_(std::move(stage)) {
    for (const auto& piece : pieces) total_ += double(piece.points.size());
    // The stage has begun: a watcher sees it long before its first piece is done.
    context_.report(stage_, 0);
  }
  void done(const TriangleMesh& piece) {
    done_ += double(piece.points.size());
    context_.report(stage_, total_ > 0 ? done_ / total_ : 1);
  }

 private:
  const RunContext& context_;
  std::string stage_;
  double total_ = 0;
  double done_ = 0;
};

void add_poisson_figures(surface::PoissonFigures& sum, const surface::PoissonFigures& part) {
  sum.input_points += part.input_points;
  sum.used_points += part.used_points;
  sum.point_cell_mm = std::max(sum.point_cell_mm, part.point_cell_mm);
  sum.solved_in_halves = sum.solved_in_halves || part.solved_in_halves;
  sum.solver_iterations += part.solver_iterations;
  sum.solve_seconds += part.solve_seconds;
  sum.mesh_seconds += part.mesh_seconds;
}

void add_repair_counts(surface::RepairCounts& sum, const surface::RepairCounts& part) {
  sum.degenerate_triangles_removed += part.degenerate_triangles_removed;
  sum.needles_before += part.needles_before;
  sum.caps_before += part.caps_before;
  sum.needles_after += part.needles_after;
  sum.caps_after += part.caps_after;
  sum.non_manifold_vertices_split += part.non_manifold_vertices_split;
  sum.holes_filled += part.holes_filled;
}

// Repairs each component's surface in place and adds it to `repaired`.
absl::Status repair_pieces(double voxel, const RunContext& context,
                           std::vector<TriangleMesh>& pieces, SurfaceResult& repaired) {
  surface::RepairParams repair_params;
  repair_params.max_collapse_length_mm = voxel;
  PieceProgress progress(context, "repair", pieces);
  for (auto& piece : pieces) {
    surface::RepairCounts counts;
    auto fixed = surface::repair_surface(piece, repair_params, context, counts);
    if (!fixed.ok()) return fixed.status();
    add_repair_counts(*repaired.repair, counts);
    progress.done(piece);
    piece = std::move(*fixed);
    repaired.mesh.append(piece);
  }
  return absl::OkStatus();
}

surface::PoissonParams poisson_params(const PoissonOptions& options, double voxel) {
  surface::PoissonParams params;
  params.min_angle_deg = options.min_angle_deg;
  params.max_edge_mm = options.max_edge_voxels * voxel;
  params.max_distance_mm = options.max_distance_voxels * voxel;
  // Half the longest edge: about the liver's mean edge at the defaults.
  params.seed_spacing_mm = params.max_edge_mm / 2;
  params.reduction = options.point_reduction;
  params.reduction_cell_mm = options.point_cell_voxels * voxel;
  params.cluster_size = options.point_cluster_size;
  params.max_points = options.max_points;
  params.split_points = options.split_points;
  // 20 voxels: each half's function is trusted from 10 voxels inside its cut
  // (measured on the liver: no seam in the distances to one solve).
  params.split_overlap_mm = 20 * voxel;
  return params;
}

}  // namespace

double voxel_size_mm(const volume::ImageGeometry& geometry) {
  return std::cbrt(geometry.voxel_volume());
}

absl::Status add_quality_surfaces(const volume::LabelVolume& volume,
                                  const volume::LabelStatistics& label, const MeshParams& params,
                                  const RunContext& context, std::vector<SurfaceResult>& surfaces,
                                  std::vector<PendingDistance>& pending,
                                  std::vector<StageTiming>& stages) {
  const double voxel = voxel_size_mm(volume.geometry);
  absl::StatusOr<Pieces> pieces;
  {
    StageTimer timer(stages, "components");
    context.report("components", 0);
    pieces = kept_component_surfaces(volume, label, params.poisson, context);
  }
  if (!pieces.ok()) return pieces.status();
  if (pieces->meshes.empty()) {
    const auto& counts = pieces->counts;
    // A label asked for by name must be meshed. One found by scanning the
    // volume (a few stray voxels of a label, say) is reported with its
    // dropped components and no surface, and the other labels go on.
    if (!params.labels.empty()) {
      return absl::FailedPreconditionError(
          cat("label ", label.label, ": no component of ", params.poisson.min_component_voxels,
              " voxels or more (min-component-voxels) is left to mesh; ", counts.dropped,
              " smaller ones, ", counts.pruned_voxels, " voxels in one-voxel strands"));
    }
    SurfaceResult dropped;
    dropped.label = label.label;
    dropped.stage = "repaired";
    dropped.components = counts;
    surfaces.push_back(std::move(dropped));
    return absl::OkStatus();
  }
  TriangleMesh marching_cubes;
  for (const auto& piece : pieces->meshes) marching_cubes.append(piece);

  SurfaceResult repaired;
  repaired.label = label.label;
  repaired.stage = "repaired";
  repaired.components = pieces->counts;
  repaired.repair.emplace();
  // The Marching Cubes side of the distance check (liver: 0.8 s) is built on
  // the second core while the surface mesher keeps one busy; without Poisson,
  // beside the repair.
  const bool to_poisson = params.surface == SurfaceMethod::kPoisson;
  std::unique_ptr<surface::DistanceReference> marching_cubes_reference;
  double reference_seconds = 0;
  auto build_reference = [&] {
    if (marching_cubes_reference != nullptr) return;
    const auto start = std::chrono::steady_clock::now();
    marching_cubes_reference =
        std::make_unique<surface::DistanceReference>(marching_cubes, voxel, context);
    marching_cubes = {};
    reference_seconds = seconds_since(start);
  };
  absl::Status prepared;
  std::vector<TriangleMesh> smoothed;
  // Both run on this thread, the caller's: only it adds to `stages`.
  auto repair = [&] {
    StageTimer timer(stages, "repair");
    prepared = repair_pieces(voxel, context, pieces->meshes, repaired);
  };
  auto smooth = [&] {
    StageTimer timer(stages, "poisson_smoothing");
    for (const auto& piece : pieces->meshes) {
      auto samples = surface::smooth_surface(piece, params.poisson.smoothing, context);
      if (!samples.ok()) {
        prepared = samples.status();
        return;
      }
      smoothed.push_back(std::move(*samples));
    }
  };
  double statistics_seconds = 0;
  auto measure_repaired = [&] {
    const auto start = std::chrono::steady_clock::now();
    repaired.statistics = surface::compute_surface_statistics(repaired.mesh);
    statistics_seconds = seconds_since(start);
  };
  if (to_poisson) {
    repair();
    // The repaired surface's figures on the second core while this one
    // smooths the pieces for Poisson (liver: 0.2 s beside 0.2 s).
    if (prepared.ok()) side_by_side(measure_repaired, smooth);
  } else {
    side_by_side(build_reference, repair);
    if (prepared.ok()) measure_repaired();
  }
  add_stage_time(stages, "surface_statistics", statistics_seconds);
  if (!prepared.ok()) return prepared;
  // The repaired surface is only an intermediate when Poisson follows: its
  // figures stay in the report, its triangles need not stay in memory.
  if (to_poisson) repaired.mesh = {};

  SurfaceResult poisson;
  if (to_poisson) {
    poisson.label = label.label;
    poisson.stage = "poisson";
    poisson.components = pieces->counts;
    poisson.poisson.emplace();
    const auto poisson_settings = poisson_params(params.poisson, voxel);
    PieceProgress progress(context, "poisson", pieces->meshes);
    for (size_t i = 0; i < pieces->meshes.size(); ++i) {
      const TriangleMesh samples = std::move(smoothed[i]);
      surface::PoissonFigures figures;
      auto smooth = surface::reconstruct_poisson_surface(
          samples.points, surface::vertex_normals(samples, params.poisson.normals),
          poisson_settings, context, figures, build_reference);
      add_stage_time(stages, "poisson_solve", figures.solve_seconds);
      add_stage_time(stages, "poisson_mesh", figures.mesh_seconds);
      if (!smooth.ok()) {
        return absl::Status(smooth.status().code(), cat("label ", label.label, ": ",
                                                        std::string(smooth.status().message())));
      }
      add_poisson_figures(*poisson.poisson, figures);
      poisson.mesh.append(*smooth);
      progress.done(pieces->meshes[i]);
    }
  }

  SurfaceResult& output = to_poisson ? poisson : repaired;
  output.is_output = true;
  if (to_poisson) {
    StageTimer timer(stages, "surface_statistics");
    poisson.statistics = surface::compute_surface_statistics(poisson.mesh);
  }
  {
    StageTimer timer(stages, "self_intersections");
    context.report("self_intersections", 0);
    output.self_intersections = surface::count_self_intersections(output.mesh);
    context.report("self_intersections", 1);
  }
  surfaces.push_back(std::move(repaired));
  if (to_poisson) surfaces.push_back(std::move(poisson));
  // Not built yet when the run ended before meshing.
  if (auto s = context.check_stop(); !s.ok()) return s;
  build_reference();
  // Part of the distance check, though it ran beside other work.
  add_stage_time(stages, "surface_distance", reference_seconds);
  pending.push_back({surfaces.size() - 1, std::move(marching_cubes_reference)});
  return absl::OkStatus();
}

absl::Status measure_distances(std::vector<SurfaceResult>& surfaces,
                               std::vector<PendingDistance>& pending, const RunContext& context) {
  context.report("surface_distance", 0);
  for (auto& measure : pending) {
    auto& surface = surfaces[measure.surface];
    surface.distance_to_marching_cubes =
        surface::surface_distance(surface.mesh, *measure.marching_cubes, context);
    measure.marching_cubes.reset();
    if (auto s = context.check_stop(); !s.ok()) return s;
  }
  pending.clear();
  context.report("surface_distance", 1);
  return absl::OkStatus();
}

absl::Status measure_distances_beside(std::vector<SurfaceResult>& surfaces,
                                      std::vector<PendingDistance>& pending,
                                      const RunContext& context,
                                      const std::function<void()>& other_work,
                                      double& distance_seconds) {
  std::vector<std::unique_ptr<surface::DistanceMeasurement>> measurements;
  // Set once `measurements` is complete; only then may this thread read it.
  std::atomic<bool> ready{false};
  side_by_side(
      [&] {
        const auto start = std::chrono::steady_clock::now();
        for (const auto& measure : pending) {
          measurements.push_back(std::make_unique<surface::DistanceMeasurement>(
              surfaces[measure.surface].mesh, *measure.marching_cubes));
        }
        ready.store(true, std::memory_order_release);
        for (auto& measurement : measurements) measurement->work(context);
        distance_seconds = seconds_since(start);
      },
      [&] {
        other_work();
        if (!ready.load(std::memory_order_acquire)) return;
        for (auto& measurement : measurements) measurement->work(context);
      });
  if (auto s = context.check_stop(); !s.ok()) return s;
  for (size_t i = 0; i < pending.size(); ++i) {
    surfaces[pending[i].surface].distance_to_marching_cubes = measurements[i]->result();
  }
  pending.clear();
  return absl::OkStatus();
}

}  // namespace labelmesh
