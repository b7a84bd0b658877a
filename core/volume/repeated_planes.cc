// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/repeated_planes.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/volume/voxel_access.h"

namespace labelmesh::volume {
namespace {

using Changes = std::array<std::vector<bool>, 3>;

template <typename T>
Changes find_changes(const T* voxels, const std::array<int64_t, 3>& dims) {
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const size_t row_bytes = sizeof(T) * size_t(nx);
  Changes changed{std::vector<bool>(size_t(nx)), std::vector<bool>(size_t(ny)),
                  std::vector<bool>(size_t(nz))};
  auto row = [&](int64_t j, int64_t k) { return voxels + (k * ny + j) * nx; };
  for (int64_t k = 1; k < nz; ++k)
    changed[2][size_t(k)] = std::memcmp(row(0, k), row(0, k - 1), row_bytes * size_t(ny)) != 0;
  // A plane of rows differs as soon as one row does.
  for (int64_t j = 1; j < ny; ++j) {
    for (int64_t k = 0; k < nz && !changed[1][size_t(j)]; ++k)
      changed[1][size_t(j)] = std::memcmp(row(j, k), row(j - 1, k), row_bytes) != 0;
  }
  // Columns: each row settles some; only the unsettled are looked at again.
  std::vector<int64_t> open;
  for (int64_t i = 1; i < nx; ++i) open.push_back(i);
  for (int64_t k = 0; k < nz && !open.empty(); ++k) {
    for (int64_t j = 0; j < ny && !open.empty(); ++j) {
      const T* r = row(j, k);
      size_t kept = 0;
      for (int64_t i : open) {
        if (r[i] == r[i - 1]) {
          open[kept++] = i;
        } else {
          changed[0][size_t(i)] = true;
        }
      }
      open.resize(kept);
    }
  }
  return changed;
}

// The common length of the runs of unchanged planes in [first, last], or 1.
int common_run(const std::vector<bool>& changed, int64_t first, int64_t last) {
  std::vector<int64_t> runs;
  int64_t start = first;
  for (int64_t p = first + 1; p <= last + 1; ++p) {
    if (p > last || changed[size_t(p)]) {
      runs.push_back(p - start);
      start = p;
    }
  }
  // The first and last runs may be cut short; at least two whole ones between.
  if (runs.size() < 4) return 1;
  const int64_t length = runs[1];
  if (length < 2) return 1;
  for (size_t r = 1; r + 1 < runs.size(); ++r) {
    if (runs[r] != length) return 1;
  }
  if (runs.front() > length || runs.back() > length) return 1;
  return static_cast<int>(length);
}

}  // namespace

Changes find_plane_changes(const LabelVolume& volume) {
  const auto& dims = volume.geometry.dims;
  Changes changed{std::vector<bool>(size_t(dims[0])), std::vector<bool>(size_t(dims[1])),
                  std::vector<bool>(size_t(dims[2]))};
  visit_voxels(volume.voxels,
               [&](const auto* voxels, size_t) { changed = find_changes(voxels, dims); });
  return changed;
}

std::array<int, 3> find_repeated_planes(const LabelVolume& volume,
                                        const VolumeStatistics& statistics) {
  std::array<int, 3> repeated{1, 1, 1};
  if (statistics.labels.empty()) return repeated;
  // The box that holds every label: outside it all planes are background.
  std::array<int64_t, 3> low = statistics.labels.front().min_index;
  std::array<int64_t, 3> high = statistics.labels.front().max_index;
  for (const auto& label : statistics.labels) {
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = std::min(low[axis], label.min_index[axis]);
      high[axis] = std::max(high[axis], label.max_index[axis]);
    }
  }
  const Changes changed = find_plane_changes(volume);
  for (int axis = 0; axis < 3; ++axis)
    repeated[axis] = common_run(changed[axis], low[axis], high[axis]);
  return repeated;
}

}  // namespace labelmesh::volume
