// SPDX-License-Identifier: AGPL-3.0-or-later
// Union-find over dense ids, with path halving: used for connected components
// of voxels and of triangles.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace labelmesh::geometry {

class DisjointSets {
 public:
  explicit DisjointSets(size_t n = 0) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }

  // Adds a singleton set and returns its id.
  uint32_t add() {
    parent_.push_back(static_cast<uint32_t>(parent_.size()));
    return parent_.back();
  }

  uint32_t find(uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  // Joins the sets of a and b; false when they were already one. The smaller
  // root survives, so roots follow first appearance.
  bool unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
    return true;
  }

  size_t size() const { return parent_.size(); }

 private:
  std::vector<uint32_t> parent_;
};

}  // namespace labelmesh::geometry
