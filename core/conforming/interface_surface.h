// SPDX-License-Identifier: AGPL-3.0-or-later
// A triangle surface made of the interfaces between labels: each triangle
// knows the label on either side, and touching labels share their triangles.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
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
  // Per triangle: the voxels behind and in front, as linear indices into the
  // padded box (x fastest): which voxel of a label each triangle bounds.
  std::vector<std::array<uint64_t, 2>> side_voxels;
  // The padded box's dimensions, and the volume index of its first voxel:
  // the box holds the selected labels and one voxel more all round.
  std::array<int64_t, 3> padded_dims{0, 0, 0};
  std::array<int64_t, 3> padded_first{-1, -1, -1};
  // The points moved to widen small angles, each with the place smoothing
  // left it (LPS mm): a move that makes triangles cross is taken back by
  // halves, then wholly (widen_small_angles.h).
  struct Slid {
    uint32_t point = 0;
    std::array<double, 3> before{0, 0, 0};
    int halvings = 0;  // times half of what was left of the move went back
  };
  std::vector<Slid> widened;
};

}  // namespace labelmesh::conforming
