// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/drawn_grid.h"

#include <vtkImageData.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/util/text.h"
#include "core/volume/repeated_planes.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::volume {
namespace {

// At most this share of the gaps between the first and last change may
// span more than one lattice step (labels that do not reach across the
// whole image); no pitch above kMaxPitch file voxels is looked for, and an
// axis with more than kMaxChanges changes is not looked at (no coarser grid
// has them, and the fit's memory stays bounded on any header's sizes).
constexpr double kMaxLongGaps = 0.25;
constexpr double kMaxPitch = 8;
constexpr size_t kMaxChanges = size_t{1} << 20;
// Pitches from kMinPitch to 2 leave gaps of one and two planes between
// changes, where a gap's count of lattice steps cannot be told: they are
// looked for only where every lattice boundary has a change (no gap longer
// than 2), with at least kMinFineChanges of them.
constexpr double kMinPitch = 1.5;
constexpr size_t kMinFineChanges = 32;

// The lattice the changes along one axis lie on, or pitch 1. Plane p
// changing means a boundary at p - 1/2.
DrawnAxis drawn_axis(const std::vector<bool>& changed) {
  DrawnAxis axis;
  axis.count = static_cast<int64_t>(changed.size());
  std::vector<int64_t> boundary;  // the changing planes
  for (size_t p = 1; p < changed.size(); ++p) {
    if (!changed[p]) continue;
    if (boundary.size() == kMaxChanges) return axis;
    boundary.push_back(static_cast<int64_t>(p));
  }
  if (boundary.size() < kMinDrawnChanges) return axis;
  std::vector<int64_t> gap(boundary.size() - 1);
  for (size_t i = 0; i + 1 < boundary.size(); ++i) gap[i] = boundary[i + 1] - boundary[i];
  const int64_t shortest = *std::min_element(gap.begin(), gap.end());
  if (static_cast<double>(shortest) > kMaxPitch) return axis;
  std::vector<double> step_at(boundary.size(), 0);
  double lowest_pitch = 2;
  double highest_pitch = kMaxPitch;
  if (shortest == 1) {
    // Every gap one lattice step of one or two planes. (Three changes in a
    // row need offsets spanning 2 (pitch - 1), more than one voxel above a
    // pitch of 1.5: the spread below rules them out.)
    if (boundary.size() < kMinFineChanges) return axis;
    for (size_t i = 0; i < gap.size(); ++i) {
      if (gap[i] > 2) return axis;
      step_at[i + 1] = step_at[i] + 1;
    }
    lowest_pitch = kMinPitch;
    highest_pitch = 2;
  } else {
    // One lattice step covers floor(pitch) or ceil(pitch) planes, so the
    // single steps are the gaps of at most shortest + 1 (two steps cover at
    // least 2 floor(pitch) >= shortest + 2). Their mean is a first pitch;
    // each gap then counts its whole number of steps.
    double single_sum = 0;
    int64_t singles = 0;
    for (int64_t g : gap) {
      if (g <= shortest + 1) {
        single_sum += static_cast<double>(g);
        ++singles;
      }
    }
    if (static_cast<double>(singles) < (1 - kMaxLongGaps) * static_cast<double>(gap.size()))
      return axis;
    const double first_pitch = single_sum / static_cast<double>(singles);
    for (size_t i = 0; i + 1 < boundary.size(); ++i)
      step_at[i + 1] = step_at[i] + std::max(1.0, std::round(double(gap[i]) / first_pitch));
  }
  const double steps = step_at.back();
  // Nearest-neighbour rounding puts each boundary within half a voxel of
  // the lattice's: their offsets from it span at most one voxel, which
  // bounds the pitch to [(span - 1) / steps, (span + 1) / steps]. The spread
  // is convex in the pitch; a ternary search finds its least.
  const auto spread = [&](double pitch, double& low, double& high) {
    low = high = 0;
    for (size_t i = 0; i < boundary.size(); ++i) {
      const double offset = double(boundary[i] - boundary.front()) - pitch * step_at[i];
      low = std::min(low, offset);
      high = std::max(high, offset);
    }
    return high - low;
  };
  const double span = static_cast<double>(boundary.back() - boundary.front());
  double below = std::max(lowest_pitch, (span - 1) / steps);
  double above = std::min(highest_pitch, (span + 1) / steps);
  if (below > above) return axis;
  double low = 0, high = 0;
  for (int i = 0; i < 60; ++i) {
    const double a = below + (above - below) / 3, b = above - (above - below) / 3;
    if (spread(a, low, high) < spread(b, low, high)) {
      above = b;
    } else {
      below = a;
    }
  }
  const double pitch = 0.5 * (below + above);
  if (spread(pitch, low, high) > 1 + 1e-9) return axis;
  // A lattice boundary: the first change's plane edge, moved to the middle
  // of the offsets. The first drawn voxel is the one holding the file's
  // first voxel centre (0), the last the one holding its last.
  const double anchor = static_cast<double>(boundary.front()) - 0.5 + 0.5 * (low + high);
  axis.pitch = pitch;
  axis.first_boundary = anchor - std::ceil(anchor / pitch) * pitch;
  const double last_centre = static_cast<double>(changed.size()) - 1;
  axis.count = static_cast<int64_t>(std::floor((last_centre - axis.first_boundary) / pitch)) + 1;
  return axis;
}

// The file voxel nearest drawn voxel c's centre along `axis`.
int64_t file_index(const DrawnAxis& axis, int64_t c, int64_t file_count) {
  const double centre = axis.first_boundary + (static_cast<double>(c) + 0.5) * axis.pitch;
  return std::clamp<int64_t>(std::llround(centre), 0, file_count - 1);
}

}  // namespace

bool DrawnGrid::resampled() const {
  return std::count_if(axes.begin(), axes.end(), [](const DrawnAxis& a) { return a.pitch > 1; }) >=
         2;
}

DrawnGrid find_drawn_grid(const LabelVolume& volume) {
  // Changes in any layer count: overlapping segments kept apart were all
  // resampled alike, or one of them was not.
  auto changed = find_plane_changes(volume);
  for (const auto& layer : volume.more_layers) {
    LabelVolume more;
    more.geometry = volume.geometry;
    more.voxels = layer;
    const auto also = find_plane_changes(more);
    for (int k = 0; k < 3; ++k)
      for (size_t p = 0; p < changed[k].size() && p < also[k].size(); ++p)
        if (also[k][p]) changed[k][p] = true;
  }
  DrawnGrid grid;
  for (int k = 0; k < 3; ++k) grid.axes[k] = drawn_axis(changed[k]);
  return grid;
}

DrawnSampling drawn_sampling(const ImageGeometry& file, const std::array<DrawnAxis, 3>& axes) {
  DrawnSampling sampling;
  sampling.geometry = file;
  std::array<double, 3> first_centre{};
  for (int k = 0; k < 3; ++k) {
    const DrawnAxis& axis = axes[k];
    sampling.geometry.dims[k] = axis.count;
    sampling.geometry.spacing[k] = file.spacing[k] * axis.pitch;
    first_centre[k] = axis.first_boundary + 0.5 * axis.pitch;
    auto& source = sampling.source[k];
    source.resize(static_cast<size_t>(std::max<int64_t>(axis.count, 0)));
    for (size_t c = 0; c < source.size(); ++c)
      source[c] = file_index(axis, static_cast<int64_t>(c), file.dims[k]);
  }
  sampling.geometry.origin = file.to_physical(first_centre);
  return sampling;
}

absl::StatusOr<LabelVolume> resample_to_drawn_grid(const LabelVolume& volume,
                                                   const DrawnGrid& grid) {
  const auto& file = volume.geometry;
  for (int k = 0; k < 3; ++k) {
    if (grid.axes[k].count < 1 || grid.axes[k].pitch < 1)
      return absl::InvalidArgumentError(cat("drawn grid: axis ", k, " has no voxel"));
  }
  DrawnSampling sampling = drawn_sampling(file, grid.axes);
  const auto& source = sampling.source;
  LabelVolume drawn;
  drawn.format = volume.format;
  drawn.file_voxel_type = volume.file_voxel_type;
  drawn.descriptions = volume.descriptions;
  drawn.geometry = sampling.geometry;
  const auto& dims = drawn.geometry.dims;
  const auto resample = [&](vtkImageData* image) -> absl::StatusOr<vtkSmartPointer<vtkImageData>> {
    const int* image_dims = image->GetDimensions();
    for (int k = 0; k < 3; ++k) {
      if (image_dims[k] != file.dims[k])
        return absl::InvalidArgumentError("drawn grid: a layer's grid differs from the volume's");
    }
    auto out = vtkSmartPointer<vtkImageData>::New();
    out->SetDimensions(static_cast<int>(dims[0]), static_cast<int>(dims[1]),
                       static_cast<int>(dims[2]));
    out->AllocateScalars(VTK_INT, 1);
    auto* to = static_cast<int32_t*>(out->GetScalarPointer());
    if (to == nullptr) {
      return absl::ResourceExhaustedError(
          cat("drawn grid: no memory for ", drawn.geometry.voxel_count(), " voxels"));
    }
    const int64_t nx = file.dims[0], ny = file.dims[1];
    const bool known = visit_voxels(image, [&](const auto* from, size_t) {
      for (int64_t z = 0; z < dims[2]; ++z)
        for (int64_t y = 0; y < dims[1]; ++y) {
          const auto* row = from + (source[2][size_t(z)] * ny + source[1][size_t(y)]) * nx;
          for (int64_t x = 0; x < dims[0]; ++x)
            *to++ = static_cast<int32_t>(row[source[0][size_t(x)]]);
        }
    });
    if (!known) return absl::InvalidArgumentError("drawn grid: a voxel type it cannot read");
    return out;
  };
  auto voxels = resample(volume.voxels);
  if (!voxels.ok()) return voxels.status();
  drawn.voxels = *voxels;
  for (const auto& layer : volume.more_layers) {
    auto more = resample(layer);
    if (!more.ok()) return more.status();
    drawn.more_layers.push_back(*more);
  }
  return drawn;
}

}  // namespace labelmesh::volume
