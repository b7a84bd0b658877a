// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_net_surfaces.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "core/conforming/label_interfaces.h"
#include "core/conforming/net_label_surface.h"
#include "core/conforming/parted_crossings.h"
#include "core/conforming/thick_slices.h"
#include "core/conforming/widen_small_angles.h"
#include "core/pipeline/label_surfaces.h"
#include "core/surface/surface_checks.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/voxel_fidelity.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

// Thin triangles are widened towards this angle where moving points inside
// their boxes can (conforming/widen_small_angles.h); below kWidenFarBelowDeg
// the points may move farther across the surface.
constexpr double kWidenAnglesBelowDeg = 30;
constexpr double kWidenFarBelowDeg = 20;

conforming::InterfaceParams interface_params(const NetOptions& options) {
  conforming::InterfaceParams params;
  params.smoothing_rounds = options.smoothing_rounds;
  params.shrink_step = options.shrink_step;
  params.inflate_step = options.inflate_step;
  params.cube_fraction = options.cube_fraction;
  params.restore_volumes = options.restore_volumes;
  params.volume_pauses = options.volume_pauses;
  params.subdivide_thick_quads = false;
  params.widen_angles_below_deg = kWidenAnglesBelowDeg;
  params.widen_far_below_deg = kWidenFarBelowDeg;
  params.split_sheets = true;
  params.follow_cap_rims = true;
  return params;
}

absl::Status check_net_options(const NetOptions& options) {
  if (options.smoothing_rounds < 0 || options.smoothing_rounds > 2000)
    return absl::InvalidArgumentError(
        cat("net smoothing rounds: ", options.smoothing_rounds, " is outside 0..2000"));
  if (!(options.shrink_step > 0 && options.shrink_step < 1 && options.inflate_step < 0 &&
        -options.inflate_step < 1))
    return absl::InvalidArgumentError("net smoothing steps: shrink in (0, 1), inflate in (-1, 0)");
  if (options.volume_pauses < 0 || options.volume_pauses > 10)
    return absl::InvalidArgumentError(
        cat("net volume pauses: ", options.volume_pauses, " is outside 0..10"));
  if (options.thin_grid_rounds_factor < 1 || options.thin_grid_rounds_factor > 8)
    return absl::InvalidArgumentError(
        cat("net thin-grid rounds factor: ", options.thin_grid_rounds_factor, " is outside 1..8"));
  if (!(options.thick_ratio >= 0 && options.thin_ratio > 0))
    return absl::InvalidArgumentError("net thick slices: ratios must be positive");
  if (!(options.cube_fraction > 0 && options.cube_fraction < 1))
    return absl::InvalidArgumentError(
        cat("net cube fraction: ", options.cube_fraction, " is outside (0, 1)"));
  // Half a voxel wider at most: with cube_fraction below 1 a point then
  // stays within a voxel of its staircase place.
  if (!(options.between_drawn_widening >= 0 && options.between_drawn_widening <= 0.5))
    return absl::InvalidArgumentError(cat("net widening between drawn slices: ",
                                          options.between_drawn_widening, " is outside [0, 0.5]"));
  return absl::OkStatus();
}

// The labels of `net` that share a triangle with another selected label.
std::vector<int32_t> touching_labels(const conforming::InterfaceSurface& net) {
  std::vector<int32_t> touching;
  for (const auto& sides : net.sides) {
    if (sides[0] == conforming::kOutside || sides[1] == conforming::kOutside) continue;
    touching.push_back(sides[0]);
    touching.push_back(sides[1]);
  }
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  return touching;
}

// Which axis of `layer` is cut into thinner slices for the net of `here`,
// if any.
conforming::ThickSlices thick_slices(const volume::LabelVolume& layer,
                                     const std::vector<int32_t>& here, const NetOptions& options) {
  if (options.thick_ratio <= 0) return {};
  conforming::ThickSliceParams params;
  params.min_ratio = options.thick_ratio;
  params.thin_ratio = options.thin_ratio;
  params.max_voxels = options.max_thin_voxels;
  return conforming::find_thick_slices(layer, here, params);
}

double anisotropy(const volume::ImageGeometry& geometry) {
  const auto& s = geometry.spacing;
  return std::max({s[0], s[1], s[2]}) / std::min({s[0], s[1], s[2]});
}

// One layer's net of `here`, on the layer's grid or on thinner slices of it
// (then with the layer's own staircase when `with_staircase`).
struct LayerNet {
  conforming::InterfaceSurface net;
  volume::ImageGeometry geometry;
  // The layer's own unsmoothed net, where the net was made on thinner slices.
  std::optional<conforming::InterfaceSurface> staircase;
};

// With `split_sheets` false, one point per cube throughout; with
// `joined_voxels`, one in the cubes with a corner among them. A net made on
// thinner slices always has one point per cube.
absl::StatusOr<LayerNet> layer_net(const volume::LabelVolume& layer,
                                   const std::vector<int32_t>& here, const NetOptions& options,
                                   bool with_staircase, const RunContext& context,
                                   std::vector<StageTiming>& stages, bool split_sheets = true,
                                   std::vector<uint64_t> joined_voxels = {}) {
  LayerNet made;
  conforming::InterfaceFigures figures;
  const auto cut = thick_slices(layer, here, options);
  if (cut.axis < 0) {
    made.geometry = layer.geometry;
    auto params = interface_params(options);
    params.split_sheets = params.split_sheets && split_sheets;
    params.joined_voxels = std::move(joined_voxels);
    made.net = conforming::label_interfaces(layer, here, params, figures);
    return made;
  }
  absl::StatusOr<volume::LabelVolume> thin;
  {
    StageTimer thick_timer(stages, "thick_slices");
    thin = conforming::interpolate_thick_slices(layer, here, cut, context);
  }
  if (!thin.ok()) return thin.status();
  made.geometry = thin->geometry;
  // Points of the thinner grid may move as far as the thick slices'.
  auto thin_params = interface_params(options);
  thin_params.box_scale[cut.axis] = cut.parts;
  thin_params.drawn_axis = cut.axis;
  thin_params.drawn_parts = cut.parts;
  thin_params.between_drawn_widening = options.between_drawn_widening;
  thin_params.smoothing_rounds = options.smoothing_rounds * options.thin_grid_rounds_factor;
  made.net = conforming::label_interfaces(*thin, here, thin_params, figures);
  if (!with_staircase) return made;
  conforming::InterfaceParams flat = interface_params(options);
  flat.smoothing_rounds = 0;
  flat.widen_angles_below_deg = 0;
  flat.follow_cap_rims = false;
  made.staircase = conforming::label_interfaces(layer, here, flat, figures);
  return made;
}

}  // namespace

// A layer's net smoothed half as many rounds, with its crossing pairs.
struct LighterNet {
  conforming::InterfaceSurface net;
  surface::TrianglePairs crossings;
};

// The lighter nets of a run, each made once, by the first label that asks;
// labels on other threads wait for it.
class LighterNets {
 public:
  explicit LighterNets(size_t layers) : built_(layers), parting_(layers) {}

  // The layer's lighter net parts its faces as its full net does: one point
  // per cube when `split` is false, else one in the cubes around `joined`.
  void part_as(size_t layer, bool split, std::vector<uint64_t> joined) {
    absl::MutexLock lock(&mutex_);
    parting_[layer] = {split, std::move(joined)};
  }

  absl::StatusOr<const LighterNet*> get(size_t layer, const volume::LabelVolume& volume,
                                        const std::vector<int32_t>& here, NetOptions options,
                                        const RunContext& context,
                                        std::vector<StageTiming>& stages) {
    absl::MutexLock lock(&mutex_);
    if (built_[layer] != nullptr) return built_[layer].get();
    options.smoothing_rounds /= 2;
    absl::StatusOr<LayerNet> made;
    {
      StageTimer timer(stages, "surface_net");
      // The staircase is the full net's: the same voxels.
      made = layer_net(volume, here, options, /*with_staircase=*/false, context, stages,
                       parting_[layer].split, parting_[layer].joined);
    }
    if (!made.ok()) return made.status();
    auto lighter = std::make_unique<LighterNet>();
    lighter->net = std::move(made->net);
    {
      StageTimer timer(stages, "self_intersections");
      lighter->crossings = conforming::crossings_after_taking_back_slides(lighter->net);
    }
    built_[layer] = std::move(lighter);
    return built_[layer].get();
  }

 private:
  // Held while a net is built: the labels that want it wait for it.
  absl::Mutex mutex_;
  std::vector<std::unique_ptr<LighterNet>> built_ ABSL_GUARDED_BY(mutex_);
  struct Parting {
    bool split = true;
    std::vector<uint64_t> joined;
  };
  std::vector<Parting> parting_ ABSL_GUARDED_BY(mutex_);
};

namespace {

// Makes the lighter net of the label's layer when first asked.
using LighterNetSource = std::function<absl::StatusOr<const LighterNet*>()>;

// What one label's guard made: the delivered surface and the attempts.
struct LabelOutcome {
  std::vector<SurfaceResult> surfaces;
  std::vector<StageTiming> stages;
};

class LabelGuard {
 public:
  // `net` was made on a grid of `net_geometry` (the layer's, or thinner
  // slices of it); `staircase`, when set, is the layer's own unsmoothed net.
  LabelGuard(const volume::LabelVolume& layer, const conforming::InterfaceSurface& net,
             const volume::ImageGeometry& net_geometry,
             const conforming::InterfaceSurface* staircase,
             const surface::TrianglePairs& net_crossings, LighterNetSource lighter,
             const volume::LabelStatistics& label, const SurfaceTolerance& tolerance,
             const MeshParams& params, const RunContext& context, LabelOutcome& outcome)
      : layer_(layer),
        net_(net),
        net_crossings_(net_crossings),
        net_geometry_(net_geometry),
        staircase_net_(staircase),
        lighter_source_(std::move(lighter)),
        label_(label),
        tolerance_(tolerance),
        params_(params),
        context_(context),
        outcome_(outcome) {
    fidelity_.tolerance = tolerance;
  }

  absl::Status run(bool poisson_first) {
    {
      StageTimer timer(outcome_.stages, "net_label_surface");
      cut_ = conforming::net_label_surface(net_, label_.label, net_geometry_);
      if (staircase_net_ != nullptr)
        voxel_boundary_ =
            conforming::net_label_surface(*staircase_net_, label_.label, layer_.geometry,
                                          conforming::SplitCrossings::kLeave)
                .staircase;
    }
    if (cut_.mesh.triangles.empty())
      return absl::InternalError(cat("label ", label_.label, ": the surface net has no triangle"));
    const double voxel = voxel_size_mm(layer_.geometry);
    const double area = surface::surface_area(cut_.mesh);
    fidelity_.thickness_voxels =
        area > 0 ? 3 * std::abs(surface::signed_volume(cut_.mesh)) / area / voxel : 0;
    const bool fall_back = params_.guard.fall_back;
    poisson_first =
        poisson_first && fidelity_.thickness_voxels >= params_.poisson.min_thickness_voxels;
    if (poisson_first) {
      LABELMESH_RETURN_IF_ERROR(try_poisson());
    }
    if (!delivered()) {
      Candidate net{cut_.mesh, {}};
      const auto* corresponding = staircase_net_ == nullptr ? &cut_.staircase : nullptr;
      LABELMESH_RETURN_IF_ERROR(measure(SurfaceAttemptMethod::kNet, net, corresponding));
    }
    if (!delivered() && lighter_source_) LABELMESH_RETURN_IF_ERROR(try_lighter_net());
    if (fall_back && !delivered() && !poisson_first) {
      LABELMESH_RETURN_IF_ERROR(try_poisson());
    }
    return deliver();
  }

 private:
  struct Candidate {
    surface::TriangleMesh mesh;
    surface::SurfaceStatistics statistics;
  };

  // The exact boundary of the label's voxels.
  const surface::TriangleMesh& voxel_boundary() const {
    return staircase_net_ != nullptr ? voxel_boundary_ : cut_.staircase;
  }

  bool delivered() const {
    return !fidelity_.attempts.empty() && fidelity_.attempts.back().within_tolerance;
  }

  // Measures `candidate` against the voxels and keeps it as an attempt.
  // `corresponding`: the same triangles on the staircase, when it has them.
  absl::Status measure(SurfaceAttemptMethod method, Candidate& candidate,
                       const surface::TriangleMesh* corresponding) {
    StageTimer timer(outcome_.stages, "voxel_fidelity");
    context_.report("voxel_fidelity", 0);
    candidate.statistics = surface::compute_surface_statistics(candidate.mesh);
    LABELMESH_ASSIGN_OR_RETURN(
        auto voxels, surface::measure_voxel_fidelity(candidate.mesh, layer_, label_, context_));
    voxels.hausdorff_voxels =
        corresponding != nullptr ? surface::corresponding_hausdorff_voxels(
                                       candidate.mesh, *corresponding, layer_.geometry)
                                 : surface::sampled_hausdorff_voxels(
                                       candidate.mesh, voxel_boundary(), layer_.geometry, context_);
    LABELMESH_RETURN_IF_ERROR(context_.check_stop());
    SurfaceAttempt attempt;
    attempt.method = method;
    attempt.volume_change = voxels.volume_change;
    attempt.min_angle_deg = candidate.statistics.min_angle_deg;
    attempt.max_angle_deg = candidate.statistics.max_angle_deg;
    attempt.voxels = voxels;
    // A surface must also be a closed manifold wound alike throughout to be
    // delivered.
    const auto& s = candidate.statistics;
    if (!s.closed || !s.manifold || !s.consistently_wound)
      attempt.error = "the surface is not a closed 2-manifold wound alike throughout";
    attempt.within_tolerance = is_within(attempt, tolerance_);
    fidelity_.attempts.push_back(std::move(attempt));
    candidates_.push_back(std::move(candidate));
    return absl::OkStatus();
  }

  // An attempt that made no surface, kept with its reason.
  void add_failed(SurfaceAttemptMethod method, std::string error) {
    SurfaceAttempt failed;
    failed.method = method;
    failed.error = std::move(error);
    fidelity_.attempts.push_back(std::move(failed));
    candidates_.push_back({});
  }

  // The label's part of the net smoothed half as many rounds.
  absl::Status try_lighter_net() {
    auto lighter = lighter_source_();
    if (!lighter.ok()) {
      if (lighter.status().code() == absl::StatusCode::kCancelled) return lighter.status();
      add_failed(SurfaceAttemptMethod::kNetLighter, std::string(lighter.status().message()));
      return absl::OkStatus();
    }
    lighter_net_ = *lighter;
    {
      StageTimer timer(outcome_.stages, "net_label_surface");
      lighter_cut_ = conforming::net_label_surface(lighter_net_->net, label_.label, net_geometry_);
    }
    Candidate candidate{lighter_cut_.mesh, {}};
    const auto* corresponding = staircase_net_ == nullptr ? &lighter_cut_.staircase : nullptr;
    return measure(SurfaceAttemptMethod::kNetLighter, candidate, corresponding);
  }

  // The Poisson path (with its own guard against Marching Cubes); its output
  // is then measured against the voxels like any other attempt.
  absl::Status try_poisson() {
    MeshParams poisson = params_;
    poisson.surface = SurfaceMethod::kPoisson;
    std::vector<SurfaceResult> made;
    auto status =
        add_label_surfaces(layer_, label_, poisson, tolerance_, context_, made, outcome_.stages);
    if (status.code() == absl::StatusCode::kCancelled) return status;
    SurfaceResult* output = nullptr;
    for (auto& s : made)
      if (s.is_output) output = &s;
    if (!status.ok() || output == nullptr) {
      add_failed(SurfaceAttemptMethod::kPoisson,
                 status.ok() ? "no surface was left once small components were dropped"
                             : std::string(status.message()));
      return absl::OkStatus();
    }
    // The repaired stage before it stays in the report (Table 2's columns).
    for (auto& s : made)
      if (!s.is_output) poisson_stages_.push_back(std::move(s));
    const auto& inner = *output->fidelity;
    const SurfaceAttemptMethod method = inner.attempts[inner.delivered].method;
    poisson_figures_ = output->poisson;
    Candidate candidate{std::move(output->mesh), {}};
    return measure(method, candidate, nullptr);
  }

  absl::Status deliver() {
    size_t best = fidelity_.attempts.size() - 1;
    if (!fidelity_.attempts.back().within_tolerance) {
      for (size_t i = 0; i < fidelity_.attempts.size(); ++i) {
        if (excess_over(fidelity_.attempts[i], tolerance_) <
            excess_over(fidelity_.attempts[best], tolerance_))
          best = i;
      }
    }
    fidelity_.delivered = best;
    const SurfaceAttempt& chosen = fidelity_.attempts[best];
    SurfaceResult output;
    output.label = label_.label;
    output.stage = method_name(chosen.method);
    output.components = ComponentCounts{};
    if (!chosen.error.empty() && candidates_[best].mesh.triangles.empty()) {
      output.error = chosen.error;
      output.fidelity = std::move(fidelity_);
      outcome_.surfaces.push_back(std::move(output));
      return absl::OkStatus();
    }
    const bool from_net = chosen.method == SurfaceAttemptMethod::kNet ||
                          chosen.method == SurfaceAttemptMethod::kNetLighter;
    if (!from_net)
      for (auto& stage : poisson_stages_) outcome_.surfaces.push_back(std::move(stage));
    output.mesh = std::move(candidates_[best].mesh);
    output.statistics = candidates_[best].statistics;
    output.components->kept = output.statistics.components;
    output.axis_aligned_share = chosen.voxels->axis_aligned_share;
    if (!from_net) output.poisson = poisson_figures_;
    output.fidelity = std::move(fidelity_);
    output.is_output = true;
    {
      StageTimer timer(outcome_.stages, "self_intersections");
      context_.report("self_intersections", 0);
      if (chosen.method == SurfaceAttemptMethod::kNet)
        output.self_intersections =
            conforming::net_label_self_intersections(net_, net_crossings_, cut_, label_.label);
      else if (chosen.method == SurfaceAttemptMethod::kNetLighter)
        output.self_intersections = conforming::net_label_self_intersections(
            lighter_net_->net, lighter_net_->crossings, lighter_cut_, label_.label);
      else
        output.self_intersections = surface::count_self_intersections(output.mesh);
    }
    outcome_.surfaces.push_back(std::move(output));
    return absl::OkStatus();
  }

  const volume::LabelVolume& layer_;
  const conforming::InterfaceSurface& net_;
  const surface::TrianglePairs& net_crossings_;
  const volume::ImageGeometry& net_geometry_;
  const conforming::InterfaceSurface* staircase_net_;
  LighterNetSource lighter_source_;
  const volume::LabelStatistics& label_;
  const SurfaceTolerance& tolerance_;
  const MeshParams& params_;
  const RunContext& context_;
  LabelOutcome& outcome_;
  conforming::NetLabelSurface cut_;
  const LighterNet* lighter_net_ = nullptr;
  conforming::NetLabelSurface lighter_cut_;
  surface::TriangleMesh voxel_boundary_;
  SurfaceFidelity fidelity_;
  std::vector<Candidate> candidates_;
  std::optional<surface::PoissonFigures> poisson_figures_;
  // What the Poisson path reported before its output (the repaired stage).
  std::vector<SurfaceResult> poisson_stages_;
};

}  // namespace

conforming::InterfaceParams net_interface_params(const NetOptions& options) {
  return interface_params(options);
}

namespace {

// The smoothed nets, without their crossings.
absl::StatusOr<LabelNets> smoothed_nets(const std::vector<volume::LabelVolume>& layers,
                                        const std::vector<size_t>& layer_of,
                                        const std::vector<int32_t>& labels,
                                        const MeshParams& params, const RunContext& context,
                                        std::vector<StageTiming>& stages) {
  const size_t count = labels.size();
  LabelNets built;
  built.nets.resize(layers.size());
  built.geometry.resize(layers.size());
  built.staircases.resize(layers.size());
  built.poisson_first.assign(count, false);
  built.crossings.resize(layers.size());
  built.layer_labels.resize(layers.size());
  built.touches_another.assign(count, false);
  built.lighter = std::make_shared<LighterNets>(layers.size());
  StageTimer timer(stages, "surface_net");
  context.report("surface_net", 0);
  for (size_t layer = 0; layer < layers.size(); ++layer) {
    std::vector<int32_t>& here = built.layer_labels[layer];
    for (size_t i = 0; i < count; ++i)
      if (layer_of[i] == layer) here.push_back(labels[i]);
    if (here.empty()) continue;
    auto made =
        layer_net(layers[layer], here, params.net, /*with_staircase=*/true, context, stages);
    if (!made.ok()) return made.status();
    built.nets[layer] = std::move(made->net);
    built.geometry[layer] = made->geometry;
    built.staircases[layer] = std::move(made->staircase);
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    const auto touching = touching_labels(built.nets[layer]);
    const bool fine_grid = anisotropy(layers[layer].geometry) <= params.net.poisson_max_anisotropy;
    for (size_t i = 0; i < count; ++i) {
      if (layer_of[i] != layer) continue;
      built.touches_another[i] = std::binary_search(touching.begin(), touching.end(), labels[i]);
      built.poisson_first[i] = fine_grid && !built.touches_another[i];
    }
  }
  context.report("surface_net", 1);
  return built;
}

// Finds each net's crossing triangle pairs, once for all its labels.
void find_net_crossings(LabelNets& built, std::vector<StageTiming>& stages) {
  StageTimer timer(stages, "self_intersections");
  for (size_t layer = 0; layer < built.nets.size(); ++layer)
    built.crossings[layer] = conforming::crossings_after_taking_back_slides(built.nets[layer]);
}

// Makes the nets whose parted faces cross again with one point in the cubes
// around the crossings, where faces a voxel apart share their points and
// cannot cross; each round joins a wider neighbourhood. Where crossings
// are left after the last round, the whole net keeps one point per cube.
absl::Status join_crossing_faces(const std::vector<volume::LabelVolume>& layers,
                                 const MeshParams& params, const RunContext& context,
                                 LabelNets& built, std::vector<StageTiming>& stages) {
  constexpr int kJoinRounds = 3;
  // Beyond this many pairs the whole net is joined at once: the voxels
  // around them would cost more memory than the parting is worth.
  constexpr size_t kMostPairsJoinedLocally = 4096;
  for (size_t layer = 0; layer < built.nets.size(); ++layer) {
    // A net on thinner slices (the one with a staircase of its own) has no
    // parted faces to join.
    if (built.staircases[layer]) continue;
    std::vector<uint64_t> joined;
    for (int round = 0; round <= kJoinRounds; ++round) {
      LABELMESH_RETURN_IF_ERROR(context.check_stop());
      const size_t pairs = crossings_between_labels(built.nets[layer], built.crossings[layer]);
      if (pairs == 0) break;
      const bool split = round < kJoinRounds && pairs <= kMostPairsJoinedLocally;
      if (split) {
        auto more = conforming::voxels_near_parted_crossings(
            built.nets[layer], built.crossings[layer], layers[layer].geometry.dims, round + 1);
        std::vector<uint64_t> all;
        std::set_union(joined.begin(), joined.end(), more.begin(), more.end(),
                       std::back_inserter(all));
        joined = std::move(all);
      }
      absl::StatusOr<LayerNet> made;
      {
        StageTimer timer(stages, "surface_net");
        made = layer_net(layers[layer], built.layer_labels[layer], params.net,
                         /*with_staircase=*/true, context, stages, split, joined);
      }
      if (!made.ok()) return made.status();
      built.nets[layer] = std::move(made->net);
      built.staircases[layer] = std::move(made->staircase);
      StageTimer timer(stages, "self_intersections");
      built.crossings[layer] = conforming::crossings_after_taking_back_slides(built.nets[layer]);
      built.lighter->part_as(layer, split, joined);
      if (!split) break;
    }
  }
  return absl::OkStatus();
}

}  // namespace

size_t crossings_between_labels(const conforming::InterfaceSurface& net,
                                const surface::TrianglePairs& crossings) {
  return static_cast<size_t>(
      std::count_if(crossings.begin(), crossings.end(), [&](const auto& pair) {
        return conforming::shares_only_outside(net, pair.first, pair.second);
      }));
}

absl::StatusOr<LabelNets> build_label_nets(const std::vector<volume::LabelVolume>& layers,
                                           const std::vector<size_t>& layer_of,
                                           const std::vector<int32_t>& labels,
                                           const MeshParams& params, const RunContext& context,
                                           std::vector<StageTiming>& stages) {
  LABELMESH_RETURN_IF_ERROR(check_net_options(params.net));
  auto built = smoothed_nets(layers, layer_of, labels, params, context, stages);
  if (!built.ok()) return built.status();
  find_net_crossings(*built, stages);
  LABELMESH_RETURN_IF_ERROR(join_crossing_faces(layers, params, context, *built, stages));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  return built;
}

absl::Status add_net_label_surface(const LabelNets& nets, size_t layer, size_t index,
                                   const volume::LabelVolume& volume,
                                   const volume::LabelStatistics& label,
                                   const SurfaceTolerance& tolerance, const MeshParams& params,
                                   const RunContext& context, std::vector<SurfaceResult>& surfaces,
                                   std::vector<StageTiming>& stages) {
  LabelOutcome outcome;
  // A label alone may take the lighter net: no neighbour's surface is cut
  // from the other one.
  LighterNetSource lighter;
  if (!nets.touches_another[index] && params.net.smoothing_rounds >= 2 && nets.lighter)
    lighter = [&]() {
      return nets.lighter->get(layer, volume, nets.layer_labels[layer], params.net, context,
                               outcome.stages);
    };
  LabelGuard guard(volume, nets.nets[layer], nets.geometry[layer],
                   nets.staircases[layer] ? &*nets.staircases[layer] : nullptr,
                   nets.crossings[layer], std::move(lighter), label, tolerance, params, context,
                   outcome);
  LABELMESH_RETURN_IF_ERROR(guard.run(nets.poisson_first[index]));
  for (auto& surface : outcome.surfaces) surfaces.push_back(std::move(surface));
  for (const auto& stage : outcome.stages) add_stage_time(stages, stage.name, stage.seconds);
  return absl::OkStatus();
}

}  // namespace labelmesh
