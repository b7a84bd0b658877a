// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/keep_label_volumes.h"

#include <algorithm>
#include <utility>

#include "core/conforming/interface_surface.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

constexpr uint32_t kMoreThanOne = UINT32_MAX;

// Gauss-Seidel sweeps of the label-graph solve in each round.
constexpr int kSolveSweeps = 200;

// The move d[l] of each label's boundary (mm, outward) that gives every
// label back `lost[l]` (mm^3) when a point between labels l and m moves by
// d[l] - d[m]: for each label, the sum over its neighbours m of
// area[l m] (d[l] - d[m]) is lost[l], with the outside's move 0. Gauss-Seidel
// sweeps; the system is a graph Laplacian held at the outside, so they
// converge where a label reaches the outside through its neighbours, and a
// label whose moving area is nil keeps d = 0.
std::vector<double> label_moves(const std::vector<std::array<uint32_t, 2>>& pairs,
                                const std::vector<double>& pair_area,
                                const std::vector<double>& lost, uint32_t outside) {
  const size_t n = lost.size();
  std::vector<std::vector<std::pair<uint32_t, double>>> around(n);
  std::vector<double> total(n, 0);
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (pair_area[k] <= 0) continue;
    const auto [l, m] = pairs[k];
    around[l].push_back({m, pair_area[k]});
    around[m].push_back({l, pair_area[k]});
    total[l] += pair_area[k];
    total[m] += pair_area[k];
  }
  std::vector<double> d(n, 0);
  for (int sweep = 0; sweep < kSolveSweeps; ++sweep) {
    for (size_t l = 0; l < n; ++l) {
      if (l == outside || total[l] <= 0) continue;
      double sum = lost[l];
      for (const auto& [m, a] : around[l]) sum += a * d[m];
      d[l] = sum / total[l];
    }
  }
  return d;
}

}  // namespace

LabelVolumeKeeper::LabelVolumeKeeper(const std::vector<std::array<uint32_t, 4>>& quads,
                                     const std::vector<std::array<int32_t, 2>>& quad_sides,
                                     const std::vector<bool>& held, const std::vector<Vec3>& centre)
    : quads_(quads), centre_(centre) {
  for (const auto& sides : quad_sides) labels_.insert(labels_.end(), sides.begin(), sides.end());
  std::sort(labels_.begin(), labels_.end());
  labels_.erase(std::unique(labels_.begin(), labels_.end()), labels_.end());
  const auto place = [&](int32_t label) {
    return static_cast<uint32_t>(std::lower_bound(labels_.begin(), labels_.end(), label) -
                                 labels_.begin());
  };
  outside_ = place(kOutside);
  if (outside_ < labels_.size() && labels_[outside_] != kOutside)
    outside_ = static_cast<uint32_t>(labels_.size());

  std::vector<std::array<uint32_t, 2>> quad_pair(quads.size());
  reversed_.resize(quads.size());
  for (size_t q = 0; q < quads.size(); ++q) {
    std::array<uint32_t, 2> sides{place(quad_sides[q][0]), place(quad_sides[q][1])};
    reversed_[q] = sides[0] == outside_ || (sides[1] != outside_ && sides[0] > sides[1]);
    if (reversed_[q]) std::swap(sides[0], sides[1]);
    quad_pair[q] = sides;
  }
  pairs_ = quad_pair;
  std::sort(pairs_.begin(), pairs_.end());
  pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
  pair_of_.resize(quads.size());
  for (size_t q = 0; q < quads.size(); ++q)
    pair_of_[q] = static_cast<uint32_t>(
        std::lower_bound(pairs_.begin(), pairs_.end(), quad_pair[q]) - pairs_.begin());
  std::vector<std::array<uint32_t, 2>>().swap(quad_pair);

  // Which points move with which pair depends on the quads alone.
  constexpr uint32_t kNone = kMoreThanOne - 1;
  point_pair_.assign(centre.size(), kNone);
  for (size_t q = 0; q < quads.size(); ++q)
    for (const uint32_t p : quads[q]) {
      if (point_pair_[p] == kNone) {
        point_pair_[p] = pair_of_[q];
      } else if (point_pair_[p] != pair_of_[q]) {
        point_pair_[p] = kMoreThanOne;
      }
    }
  for (size_t p = 0; p < centre.size(); ++p)
    if (held[p] || point_pair_[p] == kNone) point_pair_[p] = kMoreThanOne;
  moving_corners_.resize(quads.size());
  for (size_t q = 0; q < quads.size(); ++q) {
    int moving = 0;
    for (const uint32_t p : quads[q]) moving += point_pair_[p] == pair_of_[q];
    moving_corners_[q] = static_cast<uint8_t>(moving);
  }
  target_ = label_volumes(centre);
}

// Each label's enclosed volume over its quads (split 0-1-2, 0-2-3), with
// points `x`, by place: summed per pair of sides, each quad signed as wound
// from its pair's first side into its second, then a pair's sum added to
// its first side's volume and taken from its second's.
std::vector<double> LabelVolumeKeeper::label_volumes(const std::vector<Vec3>& x) const {
  std::vector<double> pair_volume(pairs_.size(), 0);
  for (size_t q = 0; q < quads_.size(); ++q) {
    const auto& c = quads_[q];
    const double v = (geometry::dot(x[c[0]], geometry::cross(x[c[1]], x[c[2]])) +
                      geometry::dot(x[c[0]], geometry::cross(x[c[2]], x[c[3]]))) /
                     6;
    pair_volume[pair_of_[q]] += reversed_[q] ? -v : v;
  }
  std::vector<double> volume(labels_.size(), 0);
  for (size_t k = 0; k < pairs_.size(); ++k) {
    volume[pairs_[k][0]] += pair_volume[k];
    volume[pairs_[k][1]] -= pair_volume[k];
  }
  return volume;
}

void LabelVolumeKeeper::restore(const PointBoxes& boxes, int rounds,
                                std::vector<Vec3>& points) const {
  // Per moving point, its area-weighted normal from its pair's first side
  // into its second.
  std::vector<Vec3> normal(points.size());
  std::vector<double> pair_area(pairs_.size()), lost(labels_.size());
  for (int round = 0; round < rounds; ++round) {
    const auto now = label_volumes(points);
    std::fill(normal.begin(), normal.end(), Vec3{0, 0, 0});
    std::fill(pair_area.begin(), pair_area.end(), 0.0);
    for (size_t q = 0; q < quads_.size(); ++q) {
      const auto& c = quads_[q];
      // Twice the quad's vector area, pointing from its first side to its
      // second.
      Vec3 n = geometry::add(geometry::cross(geometry::sub(points[c[1]], points[c[0]]),
                                             geometry::sub(points[c[2]], points[c[0]])),
                             geometry::cross(geometry::sub(points[c[2]], points[c[0]]),
                                             geometry::sub(points[c[3]], points[c[0]])));
      if (reversed_[q]) n = geometry::scale(n, -1);
      // A point moved by d along its normal moves a quarter of each of its
      // quads by d: the area each pair's moving points carry.
      pair_area[pair_of_[q]] += 0.5 * geometry::norm(n) * moving_corners_[q] / 4;
      for (const uint32_t p : c) normal[p] = geometry::add(normal[p], n);
    }
    for (size_t l = 0; l < lost.size(); ++l) lost[l] = target_[l] - now[l];
    const auto d = label_moves(pairs_, pair_area, lost, outside_);
    for (size_t p = 0; p < points.size(); ++p) {
      const double length = geometry::norm(normal[p]);
      if (point_pair_[p] == kMoreThanOne || length == 0) continue;
      const auto& [first, second] = pairs_[point_pair_[p]];
      const double move = d[first] - d[second];
      points[p] = boxes.hold(p, centre_[p],
                             geometry::add(points[p], geometry::scale(normal[p], move / length)));
    }
  }
}

}  // namespace labelmesh::conforming
