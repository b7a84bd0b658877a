// SPDX-License-Identifier: AGPL-3.0-or-later
// Thick slices (one voxel axis much coarser than the others, as in most 2D
// MR and many CT series) cut into thinner ones by shape-based interpolation:
// each label's signed distance within every slice, interpolated between
// slice centres by a cubic through the four nearest; of the labels of the
// drawn voxels below and above a thin voxel's pixel, the larger wins. A
// surface net on the thinner grid can then slope between slices
// instead of stepping a whole slice at once, which folds it.
// Reference: S. P. Raya and J. K. Udupa, "Shape-based interpolation of
// multidimensional objects", IEEE Trans. Medical Imaging 9(1), 1990.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"

namespace labelmesh::conforming {

struct ThickSliceParams {
  // An axis whose spacing is at least this many times the largest other one
  // counts as thick.
  double min_ratio = 3;
  // The thinner slices are about this many times the largest other spacing:
  // the interface surface cuts its quads near square anyway, and more
  // slices only add voxels to interpolate.
  double thin_ratio = 2;
  // At most this many thin slices per thick one, and at most this many thin
  // voxels in all (the largest volume a job may read).
  int max_parts = 8;
  int64_t max_voxels = int64_t{1} << 31;
};

struct ThickSlices {
  int axis = -1;  // -1: no axis is thick
  int parts = 1;  // thin slices per thick slice
};

// Which axis is thick, and into how many parts it is cut: its spacing over
// thin_ratio times the largest other one, rounded, from 2 to max_parts (and
// fewer when the thinner grid would exceed max_voxels; then none below 2).
ThickSlices find_thick_slices(const volume::ImageGeometry& geometry,
                              const ThickSliceParams& params);

// As above, with the thinner voxels counted over the part of `volume` that
// interpolate_thick_slices covers for `labels` (their box and the margins
// it reads), not over the whole field of view.
ThickSlices find_thick_slices(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                              const ThickSliceParams& params);

// The volume of `labels` (every non-zero label when empty; the others become
// 0) on the thinner grid: the same directions, `cut.parts` slices for each
// slice along `cut.axis`, int32 voxels, over the labels' box with two
// drawn slices more along the axis and the distances' clamp and two voxels
// more across it (clipped to the volume): outside it every thinner voxel
// would be 0. Beyond the first and last
// slice centres the labels do not change along the axis. Each label's
// distances carry a bias that keeps its volume within 1 % of its voxels'
// where a few rounds can. The bias fades to nothing at the thick slices'
// centres: a thin slice through one holds its labels, and one near it may
// differ from it at label edges.
// Errors: INVALID_ARGUMENT unless cut.axis is 0, 1 or 2, cut.parts >= 2 and
// the axis has two slices or more; RESOURCE_EXHAUSTED when the thinner
// volume cannot be allocated; CANCELLED.
absl::StatusOr<volume::LabelVolume> interpolate_thick_slices(const volume::LabelVolume& volume,
                                                             const std::vector<int32_t>& labels,
                                                             const ThickSlices& cut,
                                                             const RunContext& context);

}  // namespace labelmesh::conforming
