// SPDX-License-Identifier: AGPL-3.0-or-later
// Giving each label of a surface net back the volume its smoothing took
// (thin labels lose most): the points that lie between one pair of sides
// move along their normal, each label's boundary out by d and a point
// between two labels by the difference of theirs, with d solved over the
// graph of touching labels. A thin label between two thick ones so takes
// its volume from them, and they from their own neighbours or the outside,
// which moves nothing.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/conforming/point_boxes.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {

// Rounds of the volume step once the smoothing is done.
inline constexpr int kVolumeRounds = 6;

class LabelVolumeKeeper {
 public:
  // The net's quads, wound from quad_sides[q][0] into quad_sides[q][1]
  // (kOutside for the outside), with points at `centre` (the staircase,
  // whose volumes are the ones kept). Points `held` never move, nor do
  // points where more than one pair of sides meets, nor points in no quad.
  // `quads` and `centre` must outlive the keeper.
  LabelVolumeKeeper(const std::vector<std::array<uint32_t, 4>>& quads,
                    const std::vector<std::array<int32_t, 2>>& quad_sides,
                    const std::vector<bool>& held, const std::vector<geometry::Vec3>& centre);
  LabelVolumeKeeper(std::vector<std::array<uint32_t, 4>>&&,
                    const std::vector<std::array<int32_t, 2>>&, const std::vector<bool>&,
                    const std::vector<geometry::Vec3>&) = delete;
  LabelVolumeKeeper(const std::vector<std::array<uint32_t, 4>>&,
                    const std::vector<std::array<int32_t, 2>>&, const std::vector<bool>&,
                    std::vector<geometry::Vec3>&&) = delete;

  // `rounds` rounds of moving `points` (one per centre) towards every
  // label's volume, each point held in its box around its centre.
  void restore(const PointBoxes& boxes, int rounds, std::vector<geometry::Vec3>& points) const;

 private:
  std::vector<double> label_volumes(const std::vector<geometry::Vec3>& x) const;

  const std::vector<std::array<uint32_t, 4>>& quads_;
  const std::vector<geometry::Vec3>& centre_;
  // The labels on the quads' sides, sorted (kOutside among them): per-label
  // sums are arrays, by place in this list.
  std::vector<int32_t> labels_;
  uint32_t outside_;  // labels_.size() when no quad faces the outside
  // The pairs of sides, ordered (the outside second, two labels by place),
  // each quad's pair, and whether a quad is wound from its pair's second
  // side into its first.
  std::vector<std::array<uint32_t, 2>> pairs_;
  std::vector<uint32_t> pair_of_;
  std::vector<bool> reversed_;
  // Per point: its pair, or kMoreThanOne where it does not move; per quad:
  // how many of its corners move with its pair.
  std::vector<uint32_t> point_pair_;
  std::vector<uint8_t> moving_corners_;
  std::vector<double> target_;
};

}  // namespace labelmesh::conforming
