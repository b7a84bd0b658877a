// SPDX-License-Identifier: AGPL-3.0-or-later
// The default surfaces: every label cut from one multi-label surface net
// (conforming/label_interfaces.h), so touching labels share their
// triangles, each judged by the delivery guard against its own voxels.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/conforming/interface_surface.h"
#include "core/conforming/label_interfaces.h"
#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "core/surface/crossing_triangles.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

class LighterNets;

// The shared nets of a run: one per layer, of that layer's selected labels,
// built once before the labels are meshed.
struct LabelNets {
  std::vector<conforming::InterfaceSurface> nets;
  // The grid each net was made on: the layer's, or thinner slices of it.
  std::vector<volume::ImageGeometry> geometry;
  // The layer's own unsmoothed net, where the net was made on thinner slices.
  std::vector<std::optional<conforming::InterfaceSurface>> staircases;
  // Per label (in the order given): whether the guard tries Poisson first,
  // as the label touches no other selected label on a near-isotropic grid.
  std::vector<bool> poisson_first;
  // Per layer: the net's crossing triangle pairs, found once for all its
  // labels (every label's surface is made of the net's triangles).
  std::vector<surface::TrianglePairs> crossings;
  // Per layer: its selected labels.
  std::vector<std::vector<int32_t>> layer_labels;
  // Per label: whether it shares triangles with another selected label.
  std::vector<bool> touches_another;
  // Per layer, made when a label first needs it: the net smoothed half as
  // many rounds, for labels alone that the full smoothing takes outside the
  // voxel tolerance (thin tubes on thick slices).
  std::shared_ptr<LighterNets> lighter;
};

// The smoothing of the shared net for `options`.
conforming::InterfaceParams net_interface_params(const NetOptions& options);

// The pairs among `crossings` (triangles of `net`) that share no label but
// the outside: faces of two labels parted across a gap a voxel wide
// (conforming/cube_sheets.h) that passed through each other, which no
// label's own check sees. build_label_nets makes a net with such pairs
// again with one point in the cubes around them (one per cube everywhere
// if pairs are still left).
size_t crossings_between_labels(const conforming::InterfaceSurface& net,
                                const surface::TrianglePairs& crossings);

// Builds the nets of `labels`; `layer_of[i]` is the layer of `labels[i]`.
// Errors: INVALID_ARGUMENT for bad options, RESOURCE_EXHAUSTED when thinner
// slices cannot be allocated, CANCELLED.
absl::StatusOr<LabelNets> build_label_nets(const std::vector<volume::LabelVolume>& layers,
                                           const std::vector<size_t>& layer_of,
                                           const std::vector<int32_t>& labels,
                                           const MeshParams& params, const RunContext& context,
                                           std::vector<StageTiming>& stages);

// Appends the output surface of `label`, labels[index] of build_label_nets
// (and, when Poisson is delivered, its repaired stage). The guard's ladder,
// in order:
//   1. poisson, when nets.poisson_first[index] and the label is at least
//      params.poisson.min_thickness_voxels thick (the Poisson path with its
//      own guard, label_surfaces.h);
//   2. net: the label's part of the shared net of `layer`;
//   3. net_lighter: for a label that touches no other selected label, its
//      part of the same net smoothed half as many rounds;
//   4. the Poisson path with its mask fallbacks, when none is within the
//      tolerance.
// Every attempt is measured against the label's voxels in `volume`
// (volume, misclassified voxel centres, Hausdorff distance to the voxels'
// boundary); the first within `tolerance` is delivered, else the one least
// outside it. Errors: CANCELLED; INTERNAL when the net has no triangle of
// the label.
absl::Status add_net_label_surface(const LabelNets& nets, size_t layer, size_t index,
                                   const volume::LabelVolume& volume,
                                   const volume::LabelStatistics& label,
                                   const SurfaceTolerance& tolerance, const MeshParams& params,
                                   const RunContext& context, std::vector<SurfaceResult>& surfaces,
                                   std::vector<StageTiming>& stages);

}  // namespace labelmesh
