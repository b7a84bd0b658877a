// SPDX-License-Identifier: AGPL-3.0-or-later
// A triangle surface made of the interfaces between labels: each triangle
// knows the label on either side, and touching labels share their triangles.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace labelmesh::conforming {

// Label 0 is the outside: every voxel whose label was not selected.
inline constexpr int32_t kOutside = 0;

struct InterfaceSurface {
  // LPS, mm.
  std::vector<std::array<double, 3>> points;
  // Where each point sits on the voxels' staircase (its cube's centre), LPS mm.
  std::vector<std::array<double, 3>> staircase;
  std::vector<std::array<uint32_t, 3>> triangles;
  // Per triangle: {label behind, label in front}. The triangle's right-hand
  // normal points from sides[0] into sides[1]; the two always differ.
  std::vector<std::array<int32_t, 2>> sides;
};

}  // namespace labelmesh::conforming
