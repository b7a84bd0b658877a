// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/touching_labels.h"

#include <algorithm>
#include <map>
#include <utility>

#include "core/volume/voxel_access.h"

namespace labelmesh::volume {

std::vector<TouchingLabels> touching_labels(const LabelVolume& volume,
                                            const std::vector<int32_t>& labels) {
  std::vector<int32_t> selected = labels;
  std::sort(selected.begin(), selected.end());
  const auto counts = [&](int64_t label) {
    return label != 0 &&
           (selected.empty() || std::binary_search(selected.begin(), selected.end(), label));
  };
  const auto& dims = volume.geometry.dims;
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const int64_t steps[3] = {1, nx, nx * ny};
  std::map<std::pair<int32_t, int32_t>, uint64_t> faces;
  visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count != static_cast<size_t>(nx * ny * nz)) return;
    for (int64_t z = 0; z < nz; ++z)
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) {
          const int64_t at = x + nx * (y + ny * z);
          const int64_t here = voxels[at];
          if (here == 0) continue;
          // The neighbour one step up each axis: every face once.
          const bool inside[3] = {x + 1 < nx, y + 1 < ny, z + 1 < nz};
          for (int axis = 0; axis < 3; ++axis) {
            if (!inside[axis]) continue;
            const int64_t there = voxels[at + steps[axis]];
            if (there == here || there == 0 || !counts(here) || !counts(there)) continue;
            const auto a = static_cast<int32_t>(std::min(here, there));
            const auto b = static_cast<int32_t>(std::max(here, there));
            ++faces[{a, b}];
          }
        }
  });
  std::vector<TouchingLabels> touching;
  touching.reserve(faces.size());
  for (const auto& [pair, count] : faces) touching.push_back({pair.first, pair.second, count});
  return touching;
}

}  // namespace labelmesh::volume
