// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_surfaces.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "core/surface/component_field.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/level_set_surface.h"
#include "core/surface/smooth_surface.h"
#include "core/surface/surface_checks.h"
#include "core/surface/vertex_normals.h"
#include "core/util/side_by_side.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/label_components.h"

namespace labelmesh {
namespace {

using surface::TriangleMesh;

struct Pieces {
  ComponentCounts counts;
  // Marching Cubes surface of each kept component.
  std::vector<TriangleMesh> meshes;
  // The label's components, and the id of each kept one, for its mask.
  volume::LabelComponents components;
  std::vector<int32_t> ids;
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
  LABELMESH_ASSIGN_OR_RETURN(
      auto components, volume::find_label_components(volume, label, component_options, context));
  const uint64_t min_voxels = options.min_component_voxels;
  Pieces pieces;
  pieces.counts.pruned_voxels = components.pruned_voxels;
  pieces.counts.filled_cavities = components.filled_cavities;
  pieces.counts.filled_voxels = components.filled_voxels;
  std::vector<int32_t> kept;
  for (const auto& component : components.components) {
    if (component.voxels >= min_voxels) {
      kept.push_back(component.id);
    } else {
      ++pieces.counts.dropped;
      pieces.counts.dropped_voxels += component.voxels;
    }
  }
  pieces.counts.kept = static_cast<uint32_t>(kept.size());
  if (kept.empty()) return pieces;
  LABELMESH_ASSIGN_OR_RETURN(
      auto meshes, surface::extract_component_surfaces(components, kept, volume.geometry, context));
  pieces.meshes = std::move(meshes);
  pieces.components = std::move(components);
  pieces.ids = std::move(kept);
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
    LABELMESH_ASSIGN_OR_RETURN(auto fixed,
                               surface::repair_surface(piece, repair_params, context, counts));
    add_repair_counts(*repaired.repair, counts);
    progress.done(piece);
    piece = std::move(fixed);
    repaired.mesh.append(piece);
  }
  return absl::OkStatus();
}

// The finer Poisson attempt is made only for a first one at most this many
// times its tolerance.
constexpr double kRefineWithin = 1.5;
// The third, finest mask attempt is made only where the second one's surface
// has at most a quarter of this many points.
constexpr uint64_t kFinestMaskMaxNodes = 200'000;

// The Gaussian that smooths a label's mask before its level set is meshed,
// voxels. On the 61-label TotalSegmentator volume 0.4 kept 60 labels within
// tolerance; 0.5 and more rounded off thin parts (58), and 0.3 or none left
// creases the mesher refines without end.
constexpr double kMaskSigmaVoxels = 0.4;
// The level the mask is meshed at: a little under one half. Where the voxels
// around a point are symmetric between inside and outside (a checkerboard of
// voxels meeting along edges, say), the smoothed mask has a saddle at exactly
// one half whatever the smoothing, and the mesher refines around that pinch
// without end (the DICOM slab's label 33 at 0.5; at 0.495 it meshes promptly,
// volume -1.0 %). Just under one half such a saddle is inside, and the surface
// passes it as a neck.
constexpr double kMaskLevel = 0.495;

// Triangle sizing of one component, mm.
struct Sizing {
  double max_edge_mm = 0;
  double max_distance_mm = 0;
};

// A closed surface's thickness: 3 V / A, the radius of a ball, 1.5 radii of
// a long tube, 3 half-thicknesses of a wide plate; in each case about the
// length a smooth surface may not round off.
double thickness_mm(const TriangleMesh& piece) {
  const double area = surface::surface_area(piece);
  return area > 0 ? 3 * std::abs(surface::signed_volume(piece)) / area : 0;
}

// The sizing of a component of `label` `thickness` mm thick: the options'
// (mm, else voxels), a per-label override, else shrunk to the thickness;
// `refine` scales both lengths.
Sizing sizing_for(const PoissonOptions& options, int32_t label, double voxel, double thickness,
                  double refine) {
  Sizing sizing{
      options.max_edge_mm > 0 ? options.max_edge_mm : options.max_edge_voxels * voxel,
      options.max_distance_mm > 0 ? options.max_distance_mm : options.max_distance_voxels * voxel};
  const auto it = std::find_if(options.label_sizing.begin(), options.label_sizing.end(),
                               [label](const LabelSizing& s) { return s.label == label; });
  if (it != options.label_sizing.end()) {
    if (it->max_edge_mm > 0) sizing.max_edge_mm = it->max_edge_mm;
    if (it->max_distance_mm > 0) sizing.max_distance_mm = it->max_distance_mm;
  } else if (options.adapt_to_thickness && thickness > 0) {
    // Edges no longer than half the thickness, a distance bound a twentieth
    // of it (the torus phantom, 9 mm thick: volume -5.3 % at 8 mm edges,
    // -2.8 % at 4.5 mm); never below half a voxel and a twentieth of a voxel,
    // which the voxels cannot tell apart anyway.
    sizing.max_edge_mm = std::min(sizing.max_edge_mm, std::max(thickness / 2, voxel / 2));
    sizing.max_distance_mm = std::min(sizing.max_distance_mm, std::max(thickness / 20, voxel / 20));
  }
  sizing.max_edge_mm *= refine;
  sizing.max_distance_mm *= refine;
  return sizing;
}

surface::PoissonParams poisson_params(const PoissonOptions& options, double voxel,
                                      const Sizing& sizing) {
  surface::PoissonParams params;
  params.min_angle_deg = options.min_angle_deg;
  params.max_edge_mm = sizing.max_edge_mm;
  params.max_distance_mm = sizing.max_distance_mm;
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

// The figures of `mesh` against the label's Marching Cubes surface; returns
// the mesh's own statistics, which become the output's when it is delivered.
surface::SurfaceStatistics measure_attempt(const TriangleMesh& mesh,
                                           const surface::DistanceReference& reference,
                                           double marching_cubes_volume,
                                           const SurfaceTolerance& tolerance,
                                           const RunContext& context, SurfaceAttempt& attempt) {
  auto statistics = surface::compute_surface_statistics(mesh);
  const auto distance = surface::surface_distance(mesh, reference, context);
  attempt.volume_change =
      marching_cubes_volume > 0 ? statistics.volume_mm3 / marching_cubes_volume - 1 : 0;
  attempt.hausdorff_mm = distance.hausdorff_mm;
  attempt.hausdorff_at = distance.hausdorff_at;
  attempt.mean_distance_mm = distance.mean_mm;
  attempt.min_angle_deg = statistics.min_angle_deg;
  attempt.max_angle_deg = statistics.max_angle_deg;
  // Triangles turned against their neighbours make the inside and outside
  // disagree from one part of the surface to the next.
  if (!statistics.consistently_wound) attempt.error = "its triangles are not wound alike";
  attempt.within_tolerance = is_within(attempt, tolerance);
  return statistics;
}

}  // namespace

double voxel_size_mm(const volume::ImageGeometry& geometry) {
  return std::cbrt(geometry.voxel_volume());
}

absl::Status add_label_surfaces(const volume::LabelVolume& volume,
                                const volume::LabelStatistics& label, const MeshParams& params,
                                const SurfaceTolerance& tolerance, const RunContext& context,
                                std::vector<SurfaceResult>& surfaces,
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
  const double marching_cubes_volume = surface::signed_volume(marching_cubes);

  SurfaceResult repaired;
  repaired.label = label.label;
  repaired.stage = "repaired";
  repaired.components = pieces->counts;
  repaired.repair.emplace();
  // The Marching Cubes side of the distance check, costly on large surfaces,
  // is built on the second core while the surface mesher keeps one busy;
  // without Poisson, beside the repair.
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
  // Each component's thickness, and the label's, from its repaired surface.
  std::vector<double> thickness;
  double thickness_voxels = 0;
  auto measure_thickness = [&] {
    double volume_sum = 0, area_sum = 0;
    for (const auto& piece : pieces->meshes) {
      thickness.push_back(thickness_mm(piece));
      volume_sum += std::abs(surface::signed_volume(piece));
      area_sum += surface::surface_area(piece);
    }
    thickness_voxels = area_sum > 0 ? 3 * volume_sum / area_sum / voxel : 0;
  };
  bool try_poisson = false;
  if (to_poisson) {
    repair();
    if (prepared.ok()) {
      measure_thickness();
      try_poisson =
          !params.guard.fall_back || thickness_voxels >= params.poisson.min_thickness_voxels;
    }
    // The repaired surface's figures on the second core while this one
    // smooths the pieces for Poisson (the two take about as long as each other).
    if (prepared.ok() && try_poisson) side_by_side(measure_repaired, smooth);
    // Without Poisson, the Marching Cubes side of the distance check there.
    if (prepared.ok() && !try_poisson) side_by_side(measure_repaired, build_reference);
  } else {
    // Without Poisson the repaired surface is the output, measured below
    // as the guard's one attempt.
    side_by_side(build_reference, repair);
  }
  add_stage_time(stages, "surface_statistics", statistics_seconds);
  if (!prepared.ok()) return prepared;
  // The pieces hold the repaired surface; its figures stay in the report,
  // the joined copy need not stay in memory.
  repaired.mesh = {};

  if (!to_poisson) measure_thickness();
  SurfaceFidelity fidelity;
  fidelity.thickness_voxels = thickness_voxels;
  fidelity.tolerance = tolerance;
  fidelity.marching_cubes_volume_mm3 = marching_cubes_volume;
  // Each attempt's surface and statistics, to deliver whichever is chosen.
  struct Candidate {
    TriangleMesh mesh;
    surface::SurfaceStatistics statistics;
  };
  std::vector<Candidate> candidates;
  // Builds and measures one attempt; `build(i, sizing)` makes piece i.
  auto try_surface =
      [&](SurfaceAttemptMethod method, double refine,
          const std::function<absl::StatusOr<TriangleMesh>(size_t, const Sizing&)>& build)
      -> absl::Status {
    SurfaceAttempt attempt;
    attempt.method = method;
    TriangleMesh mesh;
    for (size_t i = 0; i < pieces->meshes.size() && attempt.error.empty(); ++i) {
      const Sizing sizing = sizing_for(params.poisson, label.label, voxel, thickness[i], refine);
      attempt.max_edge_mm = std::max(attempt.max_edge_mm, sizing.max_edge_mm);
      attempt.max_distance_mm = std::max(attempt.max_distance_mm, sizing.max_distance_mm);
      auto piece = build(i, sizing);
      if (piece.ok()) {
        mesh.append(*piece);
      } else if (piece.status().code() == absl::StatusCode::kCancelled) {
        return piece.status();
      } else {
        attempt.error = std::string(piece.status().message());
      }
    }
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    build_reference();
    surface::SurfaceStatistics statistics;
    if (attempt.error.empty()) {
      StageTimer timer(stages, "surface_distance");
      context.report("surface_distance", 0);
      statistics = measure_attempt(mesh, *marching_cubes_reference, marching_cubes_volume,
                                   tolerance, context, attempt);
    }
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    fidelity.attempts.push_back(std::move(attempt));
    candidates.push_back({std::move(mesh), statistics});
    return absl::OkStatus();
  };
  // The repaired pieces as they are.
  auto repaired_piece = [&](size_t i, const Sizing&) -> absl::StatusOr<TriangleMesh> {
    return pieces->meshes[i];
  };
  auto delivered = [&] {
    return !fidelity.attempts.empty() && fidelity.attempts.back().within_tolerance;
  };

  SurfaceResult output;
  output.label = label.label;
  output.components = pieces->counts;
  if (to_poisson) {
    const bool fall_back = params.guard.fall_back;
    // The smoothed pieces stay for the finer Poisson attempt.
    auto poisson_attempt = [&](SurfaceAttemptMethod method, double refine) {
      surface::PoissonFigures sum;
      PieceProgress progress(context, "poisson", pieces->meshes);
      auto status = try_surface(
          method, refine, [&](size_t i, const Sizing& sizing) -> absl::StatusOr<TriangleMesh> {
            const TriangleMesh& samples = smoothed[i];
            surface::PoissonFigures figures;
            auto smooth = surface::reconstruct_poisson_surface(
                samples.points, surface::vertex_normals(samples, params.poisson.normals),
                poisson_params(params.poisson, voxel, sizing), context, figures, build_reference);
            add_stage_time(stages, "poisson_solve", figures.solve_seconds);
            add_stage_time(stages, "poisson_mesh", figures.mesh_seconds);
            add_poisson_figures(sum, figures);
            progress.done(pieces->meshes[i]);
            return smooth;
          });
      if (fidelity.attempts.size() == 1) *output.poisson = sum;
      return status;
    };
    if (try_poisson) {
      output.poisson.emplace();
      LABELMESH_RETURN_IF_ERROR(poisson_attempt(SurfaceAttemptMethod::kPoisson, 1));
      // A finer Poisson surface only helps one that was nearly within: on
      // the 61-label TotalSegmentator volume it rescued two labels, both
      // within 1.5 times the tolerance, and never one further out.
      if (fall_back && !delivered() &&
          excess_over(fidelity.attempts.back(), tolerance) <= kRefineWithin) {
        LABELMESH_RETURN_IF_ERROR(poisson_attempt(SurfaceAttemptMethod::kPoissonRefined, 0.5));
      }
    }
    smoothed = {};
    // The label's voxel mask, smoothed, meshed just under one half.
    bool mask_did_not_settle = false;
    auto mask_attempt = [&](SurfaceAttemptMethod method, double refine) {
      StageTimer timer(stages, "level_set");
      context.report("level_set", 0);
      return try_surface(
          method, refine, [&](size_t i, const Sizing& sizing) -> absl::StatusOr<TriangleMesh> {
            LABELMESH_ASSIGN_OR_RETURN(auto field,
                                       surface::component_field(pieces->components, pieces->ids[i],
                                                                volume.geometry, kMaskSigmaVoxels));
            surface::LevelSetParams level_set;
            level_set.min_angle_deg = params.poisson.min_angle_deg;
            level_set.level = kMaskLevel;
            level_set.max_edge_mm = sizing.max_edge_mm;
            level_set.max_distance_mm = sizing.max_distance_mm;
            auto mesh =
                surface::mesh_level_set(field, level_set, pieces->meshes[i].points, context);
            if (mesh.status().code() == absl::StatusCode::kResourceExhausted)
              mask_did_not_settle = true;
            return mesh;
          });
    };
    // True when the last two attempts were the two mask sizings and the
    // finer one came closer.
    auto mask_closes_in = [&] {
      const size_t n = fidelity.attempts.size();
      if (n < 2) return false;
      const SurfaceAttempt& coarse = fidelity.attempts[n - 2];
      const SurfaceAttempt& fine = fidelity.attempts[n - 1];
      return coarse.method == SurfaceAttemptMethod::kMask &&
             fine.method == SurfaceAttemptMethod::kMaskRefined && coarse.error.empty() &&
             fine.error.empty() && fine.hausdorff_mm < coarse.hausdorff_mm;
    };
    if (fall_back && !delivered()) {
      LABELMESH_RETURN_IF_ERROR(mask_attempt(SurfaceAttemptMethod::kMask, 1));
    }
    // A mask the mesher could not settle on at the label's sizing has a
    // feature no finer sizing resolves, and the finer attempt would spend four
    // times the budget on it.
    if (fall_back && !delivered() && !mask_did_not_settle) {
      LABELMESH_RETURN_IF_ERROR(mask_attempt(SurfaceAttemptMethod::kMaskRefined, 0.5));
    }
    // Halving again helps a mask surface that the first halving brought
    // closer: a narrow groove that the coarser sizings bridged (brain label 8:
    // 2.95, then 1.51, then 0.64 mm). It costs about four times the points,
    // so only a surface that stays small gets it.
    if (fall_back && !delivered() && mask_closes_in() &&
        uint64_t(candidates.back().statistics.nodes) * 4 <= kFinestMaskMaxNodes) {
      LABELMESH_RETURN_IF_ERROR(mask_attempt(SurfaceAttemptMethod::kMaskFinest, 0.25));
    }
    // Last: the repaired surface itself, when nothing smoother was built.
    const bool none_built = std::none_of(fidelity.attempts.begin(), fidelity.attempts.end(),
                                         [](const SurfaceAttempt& a) { return a.error.empty(); });
    if (fall_back && none_built) {
      LABELMESH_RETURN_IF_ERROR(try_surface(SurfaceAttemptMethod::kRepaired, 1, repaired_piece));
    }
  } else {
    // The repaired surface is the output: measured, not rebuilt.
    LABELMESH_RETURN_IF_ERROR(try_surface(SurfaceAttemptMethod::kRepaired, 1, repaired_piece));
  }
  // The first attempt within the tolerance, else the one least outside it.
  fidelity.delivered = fidelity.attempts.size() - 1;
  if (!fidelity.attempts.back().within_tolerance) {
    for (size_t i = 0; i < fidelity.attempts.size(); ++i) {
      if (excess_over(fidelity.attempts[i], tolerance) <
          excess_over(fidelity.attempts[fidelity.delivered], tolerance))
        fidelity.delivered = i;
    }
  }
  const SurfaceAttempt& chosen = fidelity.attempts[fidelity.delivered];
  // With Poisson the repaired stage is listed before the output; without,
  // the output is the repaired surface itself.
  if (!to_poisson) output.repair = repaired.repair;
  if (!chosen.error.empty()) {
    // Nothing could be built: the label's error, and the run goes on.
    output.stage = to_poisson ? "poisson" : "repaired";
    output.error = chosen.error;
    output.fidelity = std::move(fidelity);
    if (to_poisson) surfaces.push_back(std::move(repaired));
    surfaces.push_back(std::move(output));
    return absl::OkStatus();
  }
  output.stage = method_name(chosen.method);
  output.mesh = std::move(candidates[fidelity.delivered].mesh);
  output.statistics = candidates[fidelity.delivered].statistics;
  output.distance_to_marching_cubes =
      surface::SurfaceDistance{chosen.hausdorff_mm, chosen.mean_distance_mm, chosen.hausdorff_at};
  output.fidelity = std::move(fidelity);
  candidates.clear();
  output.is_output = true;
  {
    StageTimer timer(stages, "self_intersections");
    context.report("self_intersections", 0);
    output.self_intersections = surface::count_self_intersections(output.mesh);
    context.report("self_intersections", 1);
  }
  add_stage_time(stages, "surface_distance", reference_seconds);
  if (to_poisson) surfaces.push_back(std::move(repaired));
  surfaces.push_back(std::move(output));
  return absl::OkStatus();
}

}  // namespace labelmesh
