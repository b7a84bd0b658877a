// SPDX-License-Identifier: AGPL-3.0-or-later
// The smallest box of voxel indices that holds every voxel a test accepts.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace labelmesh::volume {

// Inclusive voxel indices along x, y and z; empty when nothing was accepted.
struct VoxelBox {
  std::array<int64_t, 3> first{0, 0, 0};
  std::array<int64_t, 3> last{-1, -1, -1};

  bool empty() const { return last[0] < first[0]; }
};

// The box of the voxels (x fastest, `dims` of them) for which
// accepts(voxel) holds.
template <typename T, typename Accepts>
VoxelBox voxel_box(const T* voxels, const std::array<int64_t, 3>& dims, Accepts&& accepts) {
  std::array<int64_t, 3> first{dims[0], dims[1], dims[2]}, last{-1, -1, -1};
  size_t i = 0;
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x, ++i) {
        if (!accepts(voxels[i])) continue;
        const std::array<int64_t, 3> p{x, y, z};
        for (int k = 0; k < 3; ++k) {
          first[k] = std::min(first[k], p[k]);
          last[k] = std::max(last[k], p[k]);
        }
      }
  if (last[0] < 0) return {};
  return {first, last};
}

}  // namespace labelmesh::volume
