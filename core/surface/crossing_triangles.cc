// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/crossing_triangles.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>

#include "absl/container/flat_hash_map.h"

#include "core/util/side_by_side.h"

namespace labelmesh::surface {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = std::array<uint32_t, 3>;

class CrossingTest {
 public:
  CrossingTest(const std::vector<std::array<double, 3>>& points,
               const std::vector<Triangle>& triangles)
      : triangles_(triangles) {
    points_.reserve(points.size());
    for (const auto& p : points) points_.emplace_back(p[0], p[1], p[2]);
  }

  bool degenerate(uint32_t t) const {
    const auto& v = triangles_[t];
    return CGAL::collinear(points_[v[0]], points_[v[1]], points_[v[2]]);
  }

  CGAL::Bbox_3 box(uint32_t t) const {
    const auto& v = triangles_[t];
    return points_[v[0]].bbox() + points_[v[1]].bbox() + points_[v[2]].bbox();
  }

  bool cross(uint32_t a, uint32_t b) const {
    const Triangle& s = triangles_[a];
    const Triangle& t = triangles_[b];
    int shared = 0;
    int s_at = -1, t_at = -1;  // a shared corner of each
    bool s_shared[3] = {false, false, false};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (s[i] == t[j]) {
          ++shared;
          s_shared[i] = true;
          s_at = i;
          t_at = j;
        }
    if (shared == 3) return true;  // the same triangle twice
    if (shared == 2) {
      // Along a shared edge: crossing only when folded flat onto each other,
      // the two far corners on the same side of the edge.
      int s_far = 0;
      while (s_shared[s_far]) ++s_far;
      uint32_t t_far = t[0];
      for (int j = 0; j < 3; ++j)
        if (t[j] != s[(s_far + 1) % 3] && t[j] != s[(s_far + 2) % 3]) t_far = t[j];
      const Point& p = points_[s[(s_far + 1) % 3]];
      const Point& q = points_[s[(s_far + 2) % 3]];
      const Point& r = points_[s[s_far]];
      const Point& u = points_[t_far];
      return CGAL::coplanar(p, q, r, u) && CGAL::coplanar_orientation(p, q, r, u) == CGAL::POSITIVE;
    }
    // Most pairs a net's boxes give are neighbours, one wholly on one side
    // of the other's plane but for the shared point: two orientations (cheap
    // under CGAL's static filters) settle those without building triangles.
    if (apart(s, t) || apart(t, s)) return false;
    const Kernel::Triangle_3 st(points_[s[0]], points_[s[1]], points_[s[2]]);
    const Kernel::Triangle_3 tt(points_[t[0]], points_[t[1]], points_[t[2]]);
    if (shared == 1) {
      // At one shared point: crossing when the edge opposite it in either
      // triangle meets the other.
      const Kernel::Segment_3 s_opposite(points_[s[(s_at + 1) % 3]], points_[s[(s_at + 2) % 3]]);
      const Kernel::Segment_3 t_opposite(points_[t[(t_at + 1) % 3]], points_[t[(t_at + 2) % 3]]);
      return CGAL::do_intersect(st, t_opposite) || CGAL::do_intersect(tt, s_opposite);
    }
    return CGAL::do_intersect(st, tt);
  }

 private:
  // Whether t's corners that are not s's lie strictly on one side of s's
  // plane: then t meets that plane at most in a corner both share, so
  // neither t nor its edges cross s (s is not degenerate).
  bool apart(const Triangle& s, const Triangle& t) const {
    const Point& a = points_[s[0]];
    const Point& b = points_[s[1]];
    const Point& c = points_[s[2]];
    CGAL::Orientation side = CGAL::COPLANAR;
    for (const uint32_t v : t) {
      if (v == s[0] || v == s[1] || v == s[2]) continue;
      const CGAL::Orientation o = CGAL::orientation(a, b, c, points_[v]);
      if (o == CGAL::COPLANAR || (side != CGAL::COPLANAR && o != side)) return false;
      side = o;
    }
    return side != CGAL::COPLANAR;
  }

  const std::vector<Triangle>& triangles_;
  std::vector<Point> points_;
};

// The triangles' boxes in a grid whose cells are at least as wide as any
// box along each axis, each box filed under the cell of its low corner. Two
// boxes that meet then have their low corners in the same or neighbouring
// cells, so each triangle's candidates are those of 27 cells, and all the
// meeting pairs are those of each cell with itself and 13 of its neighbours.
// (CGAL's general box intersection spends its time scanning long sorted runs
// on a surface of many small boxes of one size.)
class BoxGrid {
 public:
  BoxGrid(const CrossingTest& test, size_t count) : boxes_(count) {
    for (uint32_t t = 0; t < count; ++t) boxes_[t] = test.box(t);
    if (count == 0) return;
    for (int a = 0; a < 3; ++a) {
      low_[a] = boxes_[0].min(a);
      double high = boxes_[0].max(a);
      cell_[a] = 0;
      for (const auto& b : boxes_) {
        low_[a] = std::min(low_[a], b.min(a));
        high = std::max(high, b.max(a));
        cell_[a] = std::max(cell_[a], b.max(a) - b.min(a));
      }
      // At most 2^20 cells along an axis, and never zero wide.
      cell_[a] = std::max({cell_[a], (high - low_[a]) / double(1 << 20), 1e-9});
    }
    std::vector<std::pair<uint64_t, uint32_t>> filed(count);
    for (uint32_t t = 0; t < count; ++t) filed[t] = {key(cell_of(t)), t};
    std::sort(filed.begin(), filed.end());
    order_.resize(count);
    for (size_t i = 0; i < count; ++i) {
      order_[i] = filed[i].second;
      if (i == 0 || filed[i].first != filed[i - 1].first) {
        cells_[filed[i].first] = static_cast<uint32_t>(filled_.size());
        filled_.push_back({filed[i].first, static_cast<uint32_t>(i), 0});
      }
      filled_.back().end = static_cast<uint32_t>(i + 1);
    }
  }

  // The cells holding a box, numbered in key order: how many, and the first
  // one with at least `position` triangles filed in the cells before it.
  size_t cell_count() const { return filled_.size(); }
  size_t first_cell_from(uint32_t position) const {
    return static_cast<size_t>(
        std::partition_point(filled_.begin(), filled_.end(),
                             [&](const FilledCell& cell) { return cell.begin < position; }) -
        filled_.begin());
  }

  // Calls visit(t, u) for every pair of triangles whose boxes meet and whose
  // first is filed in cells first_cell .. last_cell - 1 (of cell_count), each
  // pair over all cells once: within a cell, and with the 13 neighbouring
  // cells after it (with larger keys: z is the key's highest field). A cell's
  // neighbours are looked up once for all its triangles.
  template <typename Visit>
  void for_each_meeting_pair(size_t first_cell, size_t last_cell, Visit visit) const {
    for (size_t c = first_cell; c < last_cell; ++c) {
      const auto [cell_key, begin, end] = filled_[c];
      for (uint32_t i = begin; i < end; ++i)
        for (uint32_t j = i + 1; j < end; ++j)
          if (CGAL::do_overlap(boxes_[order_[i]], boxes_[order_[j]])) visit(order_[i], order_[j]);
      const auto at = cell_at(cell_key);
      for (int64_t dz = 0; dz <= 1; ++dz)
        for (int64_t dy = dz == 0 ? 0 : -1; dy <= 1; ++dy)
          for (int64_t dx = (dz == 0 && dy == 0) ? 1 : -1; dx <= 1; ++dx) {
            const auto found = cells_.find(key({at[0] + dx, at[1] + dy, at[2] + dz}));
            if (found == cells_.end()) continue;
            const FilledCell& other = filled_[found->second];
            for (uint32_t i = begin; i < end; ++i)
              for (uint32_t j = other.begin; j < other.end; ++j)
                if (CGAL::do_overlap(boxes_[order_[i]], boxes_[order_[j]]))
                  visit(order_[i], order_[j]);
          }
    }
  }

  // Calls visit(u) for every triangle u whose box meets t's (u != t).
  template <typename Visit>
  void for_each_meeting(uint32_t t, Visit visit) const {
    const auto c = cell_of(t);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx)
          visit_cell(t, {c[0] + dx, c[1] + dy, c[2] + dz}, visit);
  }

 private:
  template <typename Visit>
  void visit_cell(uint32_t t, const std::array<int64_t, 3>& cell, Visit&& visit) const {
    const auto found = cells_.find(key(cell));
    if (found == cells_.end()) return;
    const CGAL::Bbox_3& box = boxes_[t];
    const FilledCell& filled = filled_[found->second];
    for (uint32_t i = filled.begin; i < filled.end; ++i) {
      const uint32_t u = order_[i];
      if (u != t && CGAL::do_overlap(box, boxes_[u])) visit(u);
    }
  }

  std::array<int64_t, 3> cell_of(uint32_t t) const {
    std::array<int64_t, 3> c;
    for (int a = 0; a < 3; ++a) c[a] = int64_t((boxes_[t].min(a) - low_[a]) / cell_[a]);
    return c;
  }
  // Cells -1 .. 2^20 + 1 along each axis, 21 bits each.
  static uint64_t key(const std::array<int64_t, 3>& c) {
    return uint64_t(c[0] + 1) | uint64_t(c[1] + 1) << 21 | uint64_t(c[2] + 1) << 42;
  }
  static std::array<int64_t, 3> cell_at(uint64_t key) {
    constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
    return {int64_t(key & kMask) - 1, int64_t((key >> 21) & kMask) - 1,
            int64_t((key >> 42) & kMask) - 1};
  }

  std::vector<CGAL::Bbox_3> boxes_;
  std::array<double, 3> low_{0, 0, 0}, cell_{1, 1, 1};
  std::vector<uint32_t> order_;
  struct FilledCell {
    uint64_t key;
    uint32_t begin, end;  // its triangles in order_
  };
  std::vector<FilledCell> filled_;
  // Each filled cell's place in filled_, by key.
  absl::flat_hash_map<uint64_t, uint32_t> cells_;
};

// The crossing pairs of each triangle of `from` with the triangles whose
// boxes meet it, for which keep(from's, other) holds (each unordered pair
// must be kept once over all of `from`). Degenerate triangles, which CGAL leaves
// out of its box test, are paired with themselves instead.
template <typename Keep>
TrianglePairs crossings_from(const CrossingTest& test, const BoxGrid& grid,
                             const std::vector<uint32_t>& degenerate,
                             const std::vector<uint32_t>& from, Keep keep) {
  TrianglePairs pairs;
  for (const uint32_t s : from) {
    if (std::binary_search(degenerate.begin(), degenerate.end(), s)) {
      pairs.emplace_back(s, s);
      continue;
    }
    grid.for_each_meeting(s, [&](uint32_t t) {
      if (!keep(s, t) || std::binary_search(degenerate.begin(), degenerate.end(), t)) return;
      if (test.cross(s, t)) pairs.emplace_back(std::min(s, t), std::max(s, t));
    });
  }
  return pairs;
}

// The crossing pairs with one triangle filed in cells first_cell ..
// last_cell - 1 of `grid` and the other in the same cell or one of the 13
// neighbouring cells after it; degenerate triangles are left out
// (crossing_triangles pairs them with themselves).
TrianglePairs crossings_in_cells(const CrossingTest& test, const BoxGrid& grid,
                                 const std::vector<uint32_t>& degenerate, size_t first_cell,
                                 size_t last_cell) {
  TrianglePairs pairs;
  const auto is_degenerate = [&](uint32_t t) {
    return std::binary_search(degenerate.begin(), degenerate.end(), t);
  };
  grid.for_each_meeting_pair(first_cell, last_cell, [&](uint32_t s, uint32_t t) {
    if (!degenerate.empty() && (is_degenerate(s) || is_degenerate(t))) return;
    if (test.cross(s, t)) pairs.emplace_back(std::min(s, t), std::max(s, t));
  });
  return pairs;
}

std::vector<uint32_t> degenerate_triangles(const CrossingTest& test, size_t count) {
  std::vector<uint32_t> degenerate;
  for (uint32_t t = 0; t < count; ++t)
    if (test.degenerate(t)) degenerate.push_back(t);
  return degenerate;
}

void sort_pairs(TrianglePairs& pairs) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}

}  // namespace

TrianglePairs crossing_triangles(const std::vector<std::array<double, 3>>& points,
                                 const std::vector<std::array<uint32_t, 3>>& triangles) {
  const CrossingTest test(points, triangles);
  const uint32_t count = static_cast<uint32_t>(triangles.size());
  const std::vector<uint32_t> degenerate = degenerate_triangles(test, count);
  const BoxGrid grid(test, count);
  // The cells in two runs holding about half the triangles each, one per
  // thread.
  const size_t middle = grid.first_cell_from(count / 2);
  TrianglePairs low, high;
  side_by_side(
      [&] { low = crossings_in_cells(test, grid, degenerate, 0, middle); },
      [&] { high = crossings_in_cells(test, grid, degenerate, middle, grid.cell_count()); });
  low.insert(low.end(), high.begin(), high.end());
  for (const uint32_t t : degenerate) low.emplace_back(t, t);
  sort_pairs(low);
  return low;
}

TrianglePairs crossing_triangles_near(const std::vector<std::array<double, 3>>& points,
                                      const std::vector<std::array<uint32_t, 3>>& triangles,
                                      const std::vector<uint32_t>& among) {
  if (among.empty()) return {};
  const CrossingTest test(points, triangles);
  const uint32_t count = static_cast<uint32_t>(triangles.size());
  std::vector<bool> in_among(count, false);
  for (const uint32_t t : among) in_among[t] = true;
  const std::vector<uint32_t> degenerate = degenerate_triangles(test, count);
  const BoxGrid grid(test, count);
  // A pair inside `among` comes twice, once from each side: keep one.
  TrianglePairs pairs = crossings_from(
      test, grid, degenerate, among, [&](uint32_t s, uint32_t t) { return !in_among[t] || s < t; });
  sort_pairs(pairs);
  return pairs;
}

}  // namespace labelmesh::surface
