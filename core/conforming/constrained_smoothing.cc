// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/constrained_smoothing.h"

#include <algorithm>
#include <array>
#include <barrier>
#include <cmath>
#include <utility>

#include "core/util/side_by_side.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// Below this many points one thread smooths faster than two start.
constexpr size_t kThreadedSmoothingPoints = 20'000;

// A point's three coordinates and a spare in single precision: one step's
// sums and clamps are a few vector operations, on two thirds of the memory.
// Single precision holds a place 500 mm from the origin to 0.00003 mm; after
// all the rounds the points lie within 0.001 mm of the double-precision
// ones on the DICOM slab. A box centre's spare is 1 where the box widens
// between drawn slices (PointBoxes::widens) and 0 elsewhere, so the flag is
// loaded with the centre; the clamps' spares are 0, so a place's spare stays
// 0 and is never read.
using Lanes = float __attribute__((vector_size(16)));

Lanes to_lanes(const Vec3& v) {
  return Lanes{static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 0};
}

}  // namespace

void smooth_in_boxes(const Stencil& stencil, const std::vector<Vec3>& centre,
                     const PointBoxes& point_boxes, const InterfaceParams& params, int rounds,
                     std::vector<Vec3>& points) {
  const Vec3& half_box = point_boxes.half;
  const size_t n = points.size();
  // Step s reads places[s % 2] and writes places[(s + 1) % 2]; an even
  // number of steps ends in the first.
  std::vector<Lanes> now(n), next(n), centres(n);
  // Points without neighbours do not move: they keep their places exactly.
  std::vector<std::pair<uint32_t, Vec3>> fixed;
  for (size_t p = 0; p < n; ++p) {
    now[p] = to_lanes(points[p]);
    centres[p] = to_lanes(centre[p]);
    centres[p][3] = point_boxes.widens(p) ? 1.0f : 0.0f;
    if (stencil.start[p] == stencil.start[p + 1])
      fixed.emplace_back(static_cast<uint32_t>(p), points[p]);
  }
  // The double places are let go while the lanes are in use and made again
  // at the end.
  std::vector<Vec3>().swap(points);
  const Lanes half = to_lanes(half_box);
  const int drawn = point_boxes.drawn_axis;
  const BetweenDrawn<float> between_drawn_slices(point_boxes.drawn_first,
                                                 point_boxes.drawn_spacing);
  const Lanes widening = to_lanes(point_boxes.widening);
  const Lanes edge_low = to_lanes(point_boxes.edge_low);
  const Lanes edge_high = to_lanes(point_boxes.edge_high);
  // Along a drawn axis each point's limits (PointBoxes::along_drawn), found
  // once in double precision and rounded towards the centre, so that the
  // steps pick the same drawn slices as the final hold.
  std::vector<std::array<float, 2>> along;
  if (drawn >= 0) {
    along.resize(n);
    for (size_t p = 0; p < n; ++p) {
      const auto [low, high] = point_boxes.along_drawn(centre[p][drawn]);
      along[p] = {std::nextafter(static_cast<float>(low), static_cast<float>(centre[p][drawn])),
                  std::nextafter(static_cast<float>(high), static_cast<float>(centre[p][drawn]))};
    }
  }
  const std::array<Lanes*, 2> places{now.data(), next.data()};
  const auto step_range = [&](int step, size_t begin, size_t end) {
    const auto factor =
        static_cast<float>(step % 2 == 0 ? params.shrink_step : params.inflate_step);
    const uint32_t* __restrict start = stencil.start.data();
    const uint32_t* __restrict neighbours = stencil.neighbours.data();
    const Lanes* __restrict box = centres.data();
    const Lanes* __restrict from = places[step % 2];
    Lanes* __restrict to = places[(step + 1) % 2];
    for (size_t p = begin; p < end; ++p) {
      const uint32_t first = start[p];
      const uint32_t last = start[p + 1];
      if (first == last) {
        to[p] = from[p];
        continue;
      }
      Lanes sum{0, 0, 0, 0};
      // Most points have four neighbours: a branch that predicts well.
      if (last - first == 4) {
        sum = (from[neighbours[first]] + from[neighbours[first + 1]]) +
              (from[neighbours[first + 2]] + from[neighbours[first + 3]]);
        sum *= 0.25f;
      } else {
        for (uint32_t i = first; i < last; ++i) sum += from[neighbours[i]];
        sum *= 1.0f / static_cast<float>(last - first);
      }
      const Lanes at = from[p];
      Lanes moved = at + factor * (sum - at);
      // Pinned axes first: the widening follows from where the point is.
      if (const uint8_t axes = point_boxes.pinned_axes(p); axes != 0) {
        for (int k = 0; k < 3; ++k)
          if (axes & (1u << k)) moved[k] = box[p][k];
      }
      Lanes width = half;
      if (drawn >= 0) {
        // Along the drawn axis first: the width across follows from there.
        moved[drawn] = std::clamp(moved[drawn], along[p][0], along[p][1]);
        width += (box[p][3] * between_drawn_slices(moved[drawn])) * widening;
      }
      Lanes lo = box[p] - width, hi = box[p] + width;
      lo = lo < edge_low ? edge_low : lo;
      hi = edge_high < hi ? edge_high : hi;
      moved = moved < lo ? lo : moved;
      to[p] = hi < moved ? hi : moved;
    }
  };
  const int steps = 2 * rounds;
  if (n < kThreadedSmoothingPoints) {
    for (int s = 0; s < steps; ++s) step_range(s, 0, n);
  } else {
    // Each point's next place reads only the current places: two threads
    // share the points for the whole run and meet after every step, with
    // the same result as one.
    std::barrier<> stepped(2);
    const auto run_half = [&](size_t begin, size_t end) {
      for (int s = 0; s < steps; ++s) {
        step_range(s, begin, end);
        stepped.arrive_and_wait();
      }
    };
    side_by_side([&] { run_half(n / 2, n); }, [&] { run_half(0, n / 2); });
  }
  std::vector<Lanes>().swap(next);
  std::vector<Lanes>().swap(centres);
  // Back in double precision, held in the boxes as the double sums would be
  // (a single-precision clamp can leave a point a rounding outside).
  points.resize(n);
  for (size_t p = 0; p < n; ++p)
    points[p] = point_boxes.hold(p, centre[p],
                                 {static_cast<double>(now[p][0]), static_cast<double>(now[p][1]),
                                  static_cast<double>(now[p][2])});
  for (const auto& [p, place] : fixed) points[p] = place;
}

}  // namespace labelmesh::conforming
