// SPDX-License-Identifier: AGPL-3.0-or-later
// The surface net's cubes, marked where a point lies and numbered by rank.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace labelmesh::conforming {

// What MarkedCubes::point answers for a cube without a point.
inline constexpr uint32_t kNoPoint = UINT32_MAX;

// The cubes between voxel centres: cube (a, b, c) has the padded voxels
// (a..a+1, b..b+1, c..c+1) as corners. The cubes with a point are marked
// and their points numbered in cube index order, so a cube's point is the
// count of marked cubes before it: one bit per cube and a running count per
// 64 cubes, a twentieth of the memory of a point number per cube.
class MarkedCubes {
 public:
  explicit MarkedCubes(const std::array<int64_t, 3>& dims)
      : dims_(dims), marked_((static_cast<size_t>(dims[0] * dims[1] * dims[2]) + 63) / 64, 0) {}

  const std::array<int64_t, 3>& dims() const { return dims_; }
  size_t index(int64_t a, int64_t b, int64_t c) const {
    return static_cast<size_t>((c * dims_[1] + b) * dims_[0] + a);
  }
  std::array<int64_t, 3> cube(size_t index) const {
    const auto i = static_cast<int64_t>(index);
    return {i % dims_[0], (i / dims_[0]) % dims_[1], i / (dims_[0] * dims_[1])};
  }

  void mark(size_t index) { marked_[index / 64] |= uint64_t{1} << (index % 64); }
  // Numbers the marked cubes; after this `point` answers.
  void number() {
    before_.resize(marked_.size());
    uint32_t count = 0;
    for (size_t w = 0; w < marked_.size(); ++w) {
      before_[w] = count;
      count += static_cast<uint32_t>(std::popcount(marked_[w]));
    }
    points_ = count;
  }
  size_t points() const { return points_; }
  // The cube's point, or kNoPoint.
  uint32_t point(size_t index) const {
    const uint64_t word = marked_[index / 64];
    const uint64_t bit = uint64_t{1} << (index % 64);
    if ((word & bit) == 0) return kNoPoint;
    return before_[index / 64] + static_cast<uint32_t>(std::popcount(word & (bit - 1)));
  }
  // visit(cube index, point) for every marked cube, in index order.
  template <typename Visit>
  void for_each_point(Visit&& visit) const {
    for (size_t w = 0; w < marked_.size(); ++w) {
      uint32_t p = before_[w];
      for (uint64_t word = marked_[w]; word != 0; word &= word - 1, ++p)
        visit(64 * w + static_cast<size_t>(std::countr_zero(word)), p);
    }
  }

 private:
  std::array<int64_t, 3> dims_;
  std::vector<uint64_t> marked_;  // bit i % 64 of word i / 64: cube i has a point
  std::vector<uint32_t> before_;  // marked cubes in the words before
  size_t points_ = 0;
};

}  // namespace labelmesh::conforming
