// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/parted_crossings.h"

#include <algorithm>

namespace labelmesh::conforming {

bool shares_only_outside(const InterfaceSurface& net, uint32_t a, uint32_t b) {
  for (const int32_t x : net.sides[a])
    for (const int32_t y : net.sides[b])
      if (x == y && x != kOutside) return false;
  return true;
}

std::vector<uint64_t> voxels_near_parted_crossings(const InterfaceSurface& net,
                                                   const surface::TrianglePairs& crossings,
                                                   const std::array<int64_t, 3>& dims, int reach) {
  const auto& padded = net.padded_dims;
  std::vector<uint64_t> voxels;
  const auto add_around = [&](uint64_t padded_index) {
    const auto i = static_cast<int64_t>(padded_index);
    const std::array<int64_t, 3> at{net.padded_first[0] + i % padded[0],
                                    net.padded_first[1] + (i / padded[0]) % padded[1],
                                    net.padded_first[2] + i / (padded[0] * padded[1])};
    for (int64_t z = std::max<int64_t>(at[2] - reach, 0);
         z <= std::min<int64_t>(at[2] + reach, dims[2] - 1); ++z)
      for (int64_t y = std::max<int64_t>(at[1] - reach, 0);
           y <= std::min<int64_t>(at[1] + reach, dims[1] - 1); ++y)
        for (int64_t x = std::max<int64_t>(at[0] - reach, 0);
             x <= std::min<int64_t>(at[0] + reach, dims[0] - 1); ++x)
          voxels.push_back(static_cast<uint64_t>((z * dims[1] + y) * dims[0] + x));
  };
  for (const auto& [a, b] : crossings) {
    if (!shares_only_outside(net, a, b)) continue;
    for (const uint32_t t : {a, b})
      for (const uint64_t voxel : net.side_voxels[t]) add_around(voxel);
  }
  std::sort(voxels.begin(), voxels.end());
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  return voxels;
}

}  // namespace labelmesh::conforming
