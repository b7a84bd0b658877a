// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/label_interfaces.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "core/conforming/cap_rims.h"
#include "core/conforming/constrained_smoothing.h"
#include "core/conforming/cube_sheets.h"
#include "core/conforming/keep_label_volumes.h"
#include "core/conforming/marked_cubes.h"
#include "core/conforming/widen_small_angles.h"
#include "core/util/side_by_side.h"
#include "core/util/vec3.h"
#include "core/volume/voxel_access.h"
#include "core/volume/voxel_box.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// The selected labels' box of the volume with a ring of outside voxels
// around it, so every surface closes.
struct PaddedLabels {
  std::array<int64_t, 3> dims{0, 0, 0};
  // Volume index of padded voxel (0, 0, 0).
  std::array<int64_t, 3> first{-1, -1, -1};
  std::vector<int32_t> labels;

  int32_t at(int64_t x, int64_t y, int64_t z) const {
    return labels[static_cast<size_t>((z * dims[1] + y) * dims[0] + x)];
  }
};

PaddedLabels padded_labels(const volume::LabelVolume& volume, std::vector<int32_t> selected) {
  std::sort(selected.begin(), selected.end());
  const auto& dims = volume.geometry.dims;
  const auto chosen = [&](int32_t label) {
    return label != kOutside &&
           (selected.empty() || std::binary_search(selected.begin(), selected.end(), label));
  };
  volume::VoxelBox box;
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count != static_cast<size_t>(dims[0] * dims[1] * dims[2])) return;
    box = volume::voxel_box(voxels, dims,
                            [&](auto label) { return chosen(static_cast<int32_t>(label)); });
  });
  PaddedLabels padded;
  // With no selected voxel, a ring around one outside voxel.
  const bool none = box.empty();
  if (none) box.last = box.first;
  const auto& lo = box.first;
  const auto& hi = box.last;
  for (int a = 0; a < 3; ++a) {
    padded.first[a] = lo[a] - 1;
    padded.dims[a] = hi[a] - lo[a] + 3;
  }
  padded.labels.assign(static_cast<size_t>(padded.dims[0] * padded.dims[1] * padded.dims[2]),
                       kOutside);
  if (none) return padded;
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count != static_cast<size_t>(dims[0] * dims[1] * dims[2])) return;
    for (int64_t z = lo[2]; z <= hi[2]; ++z) {
      for (int64_t y = lo[1]; y <= hi[1]; ++y) {
        size_t in = static_cast<size_t>((z * dims[1] + y) * dims[0] + lo[0]);
        size_t out = static_cast<size_t>(
            ((z - padded.first[2]) * padded.dims[1] + y - padded.first[1]) * padded.dims[0] + 1);
        for (int64_t x = lo[0]; x <= hi[0]; ++x, ++in, ++out) {
          const auto label = static_cast<int32_t>(voxels[in]);
          if (chosen(label)) padded.labels[out] = label;
        }
      }
    }
  });
  return padded;
}

// Labels of fewer voxels than this (of the grid drawn, not of thinner
// slices cut from it) keep sharp junction curves around them
// (smoothing_stencil): moving their junction points takes too large a part
// of their volume (the frog's tissues of 4 to 121 voxels lost 11 to 49 %).
constexpr uint64_t kSharpJunctionLabelVoxels = 500;

// Labels of fewer voxels than this keep their voxels' shape: every point
// next to them stays. Smoothed, the frog's tissue of four lone voxels, each
// where three other labels meet, kept 62 % of its volume, and the volume
// step cannot give it back: it moves no point where three labels meet.
constexpr uint64_t kFixedLabelVoxels = 27;

// The labels next to which junction curves are held sharp, and those next
// to which every point stays (each sorted).
struct SmallLabels {
  std::vector<int32_t> sharp;
  std::vector<int32_t> fixed;
};

// The labels of `labels` with fewer than kSharpJunctionLabelVoxels (and
// kFixedLabelVoxels) voxels times `parts` (the thinner slices each drawn
// one was cut into).
SmallLabels small_labels(const PaddedLabels& labels, int parts) {
  std::unordered_map<int32_t, uint64_t> voxels;
  const auto& all = labels.labels;
  for (size_t run = 0; run < all.size();) {
    size_t end = run + 1;
    while (end < all.size() && all[end] == all[run]) ++end;
    voxels[all[run]] += end - run;
    run = end;
  }
  SmallLabels small;
  const auto times = uint64_t(std::max(parts, 1));
  for (const auto& [label, count] : voxels) {
    if (label == kOutside) continue;
    if (count < kSharpJunctionLabelVoxels * times) small.sharp.push_back(label);
    if (count < kFixedLabelVoxels * times) small.fixed.push_back(label);
  }
  std::sort(small.sharp.begin(), small.sharp.end());
  std::sort(small.fixed.begin(), small.fixed.end());
  return small;
}

struct Net {
  // Positions in scaled voxel space: index times spacing, mm along each axis.
  std::vector<Vec3> centre;
  // Distinct labels among the cube's corners, or on the point's sheets
  // where cubes hold a point per sheet.
  std::vector<uint8_t> label_count;
  // Where cubes hold a point per sheet (cube_sheets.h): each numbered
  // cube's first point, and one past the last; empty otherwise.
  std::vector<uint32_t> first_point;
  // There too, per point: whether its sheets hold a label in
  // SmallLabels::sharp, and one in SmallLabels::fixed (small_labels).
  std::vector<bool> near_small;
  std::vector<bool> near_fixed;
  std::vector<std::array<uint32_t, 4>> quads;
  std::vector<std::array<int32_t, 2>> quad_sides;
  std::vector<uint8_t> quad_axis;                    // the axis between the quad's two voxels
  std::vector<std::array<uint64_t, 2>> quad_voxels;  // padded linear indices
};

// The labels at the corners of cube (a, b, c), corner k at offsets k & 1,
// (k >> 1) & 1 and k >> 2.
std::array<int32_t, 8> corners(const PaddedLabels& labels, int64_t a, int64_t b, int64_t c) {
  std::array<int32_t, 8> corner{};
  for (int k = 0; k < 8; ++k) corner[k] = labels.at(a + (k & 1), b + ((k >> 1) & 1), c + (k >> 2));
  return corner;
}

uint8_t distinct_labels(const std::array<int32_t, 8>& corner) {
  std::array<int32_t, 8> seen{};
  uint8_t count = 0;
  for (const int32_t label : corner)
    if (std::find(seen.begin(), seen.begin() + count, label) == seen.begin() + count)
      seen[count++] = label;
  return count;
}

// A face-neighbouring voxel pair: the first voxel's padded coordinates and
// the axis to the second. Kept small (a CT slab has hundreds of thousands):
// volumes hold at most 2^31 voxels, so the coordinates fit 32 bits.
struct VoxelPair {
  std::array<uint32_t, 3> padded;
  uint32_t axis;

  std::array<int64_t, 3> voxel() const { return {padded[0], padded[1], padded[2]}; }
};

// The face-neighbouring voxel pairs with different labels, axis by axis and
// each axis in index order.
std::vector<VoxelPair> differing_pairs(const PaddedLabels& labels) {
  std::vector<VoxelPair> pairs;
  const auto& dims = labels.dims;
  const std::array<size_t, 3> stride{1, static_cast<size_t>(dims[0]),
                                     static_cast<size_t>(dims[0] * dims[1])};
  for (int axis = 0; axis < 3; ++axis) {
    for (int64_t z = 0; z < dims[2] - (axis == 2 ? 1 : 0); ++z) {
      for (int64_t y = 0; y < dims[1] - (axis == 1 ? 1 : 0); ++y) {
        const size_t row = static_cast<size_t>((z * dims[1] + y) * dims[0]);
        const int64_t end = dims[0] - (axis == 0 ? 1 : 0);
        for (int64_t x = 0; x < end; ++x) {
          const size_t i = row + static_cast<size_t>(x);
          if (labels.labels[i] != labels.labels[i + stride[axis]])
            pairs.push_back(
                {{static_cast<uint32_t>(x), static_cast<uint32_t>(y), static_cast<uint32_t>(z)},
                 static_cast<uint32_t>(axis)});
        }
      }
    }
  }
  return pairs;
}

// The cube at `offset` (as in the quads: {1, 1}, {0, 1}, {0, 0}, {1, 0}
// along u and v) around the segment from padded voxel p along `axis`.
std::array<int64_t, 3> cube_around(std::array<int64_t, 3> p, int axis, std::array<int, 2> offset) {
  p[(axis + 1) % 3] -= offset[0];
  p[(axis + 2) % 3] -= offset[1];
  return p;
}

constexpr std::array<std::array<int, 2>, 4> kQuadOffsets{{{1, 1}, {0, 1}, {0, 0}, {1, 0}}};

// Whether any of a cube's corners holds a label in `small` (sorted).
bool holds_small(const std::array<int32_t, 8>& corner, const std::vector<int32_t>& small) {
  return std::any_of(corner.begin(), corner.end(), [&](int32_t label) {
    return std::binary_search(small.begin(), small.end(), label);
  });
}

// Whether a corner of padded cube (a, b, c) is one of `joined` (sorted
// linear indices into the volume of `dims`).
bool touches_joined(const PaddedLabels& labels, const std::array<int64_t, 3>& dims,
                    const std::vector<uint64_t>& joined, int64_t a, int64_t b, int64_t c) {
  if (joined.empty()) return false;
  for (int k = 0; k < 8; ++k) {
    const std::array<int64_t, 3> v{a + (k & 1) + labels.first[0],
                                   b + ((k >> 1) & 1) + labels.first[1],
                                   c + (k >> 2) + labels.first[2]};
    if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= dims[0] || v[1] >= dims[1] || v[2] >= dims[2])
      continue;
    const auto index = static_cast<uint64_t>((v[2] * dims[1] + v[1]) * dims[0] + v[0]);
    if (std::binary_search(joined.begin(), joined.end(), index)) return true;
  }
  return false;
}

// The net's points, one per cube whose corners hold more than one label,
// numbered in cube index order.
// With `split`, a point per sheet through the cube (cube_sheets.h), but one
// in cubes with a corner among `joined` (touches_joined), and `small`
// marks the points next to small labels (Net::near_small, near_fixed).
Net net_points(const PaddedLabels& labels, const std::array<double, 3>& spacing,
               const std::vector<VoxelPair>& pairs, MarkedCubes& cubes, bool split,
               const SmallLabels& small, const std::array<int64_t, 3>& dims,
               const std::vector<uint64_t>& joined) {
  // A cube's corners hold more than one label exactly when one of its edges
  // joins two different labels, and every such edge's quad uses the four
  // cubes around it: mark those, then number them in index order.
  for (const auto& pair : pairs) {
    for (const auto& offset : kQuadOffsets) {
      const auto cube = cube_around(pair.voxel(), static_cast<int>(pair.axis), offset);
      cubes.mark(cubes.index(cube[0], cube[1], cube[2]));
    }
  }
  cubes.number();
  Net net;
  net.centre.reserve(cubes.points());
  net.label_count.reserve(cubes.points());
  if (split) net.first_point.reserve(cubes.points() + 1);
  cubes.for_each_point([&](size_t i, uint32_t) {
    const auto [a, b, c] = cubes.cube(i);
    // Padded voxel a is voxel a + first; the cube's centre is half a voxel
    // on.
    const auto& f = labels.first;
    const Vec3 centre{(double(a + f[0]) + 0.5) * spacing[0], (double(b + f[1]) + 0.5) * spacing[1],
                      (double(c + f[2]) + 0.5) * spacing[2]};
    const auto corner = corners(labels, a, b, c);
    if (!split) {
      net.centre.push_back(centre);
      net.label_count.push_back(distinct_labels(corner));
      return;
    }
    net.first_point.push_back(static_cast<uint32_t>(net.centre.size()));
    if (touches_joined(labels, dims, joined, a, b, c)) {
      net.centre.push_back(centre);
      net.label_count.push_back(distinct_labels(corner));
      net.near_small.push_back(holds_small(corner, small.sharp));
      net.near_fixed.push_back(holds_small(corner, small.fixed));
      return;
    }
    const CubeSheets sheets = cube_sheets(corner);
    for (int g = 0; g < sheets.sheet_count; ++g) {
      net.centre.push_back(centre);
      net.label_count.push_back(sheets.labels[g]);
      bool near_sharp = false;
      bool near_fixed = false;
      for (int k = 0; k < sheets.pair_count; ++k)
        if (sheets.sheet[k] == g)
          for (const int32_t label : sheets.pairs[k]) {
            near_sharp =
                near_sharp || std::binary_search(small.sharp.begin(), small.sharp.end(), label);
            near_fixed =
                near_fixed || std::binary_search(small.fixed.begin(), small.fixed.end(), label);
          }
      net.near_small.push_back(near_sharp);
      net.near_fixed.push_back(near_fixed);
    }
  });
  if (split) net.first_point.push_back(static_cast<uint32_t>(net.centre.size()));
  return net;
}

// One quad per pair of face neighbours with different labels, wound so its
// normal points from the first voxel to the second: the four cubes around
// their common axis, counter-clockwise seen from the second voxel.
void add_quads(const PaddedLabels& labels, const std::vector<VoxelPair>& pairs,
               const MarkedCubes& cubes, Net& net) {
  const std::array<uint64_t, 3> stride{1, static_cast<uint64_t>(labels.dims[0]),
                                       static_cast<uint64_t>(labels.dims[0] * labels.dims[1])};
  for (const auto& pair : pairs) {
    const auto voxel = pair.voxel();
    const auto axis = static_cast<int>(pair.axis);
    const auto i =
        static_cast<uint64_t>((voxel[2] * labels.dims[1] + voxel[1]) * labels.dims[0] + voxel[0]);
    const int32_t from = labels.labels[i], to = labels.labels[i + stride[axis]];
    std::array<uint32_t, 4> quad{};
    for (int k = 0; k < 4; ++k) {
      const auto cube = cube_around(voxel, axis, kQuadOffsets[k]);
      const uint32_t rank = cubes.point(cubes.index(cube[0], cube[1], cube[2]));
      if (net.first_point.empty()) {
        quad[k] = rank;
        continue;
      }
      // The point of this pair's sheet in that cube.
      const uint32_t first = net.first_point[rank];
      if (net.first_point[rank + 1] == first + 1) {
        quad[k] = first;
        continue;
      }
      const int sheet = cube_sheets(corners(labels, cube[0], cube[1], cube[2])).sheet_of(from, to);
      quad[k] = first + static_cast<uint32_t>(std::max(sheet, 0));
    }
    net.quads.push_back(quad);
    net.quad_sides.push_back({from, to});
    net.quad_axis.push_back(static_cast<uint8_t>(axis));
    net.quad_voxels.push_back({i, i + stride[axis]});
  }
}

// Whether a junction curve turns at `cube` (its neighbours along two
// axes) and again at the cube diagonal to it, which holds a junction point
// too: then it runs round three sides of one quad, and smoothed along itself
// it would lie on the straight line between the quad's ends, collapsing the
// quad onto it. Such a point stays where it is.
bool turns_back(const std::array<int64_t, 3>& cube,
                const std::array<std::array<int64_t, 3>, 2>& neighbours, const MarkedCubes& cubes,
                const Net& net) {
  std::array<int64_t, 3> diagonal = cube;
  int axes = 0;
  for (int k = 0; k < 3; ++k) {
    const int64_t step = (neighbours[0][k] - cube[k]) + (neighbours[1][k] - cube[k]);
    diagonal[k] += step;
    axes += step != 0;
  }
  if (axes != 2) return false;  // straight on
  const uint32_t r = cubes.point(cubes.index(diagonal[0], diagonal[1], diagonal[2]));
  return r != kNoPoint && net.label_count[r] > 2;
}

// A junction point `p` held to its curve (next to a small label, or with
// fewer than two junction neighbours): its neighbours from `first` on give
// way to its `on_curve` == 2 neighbours on the curve, `curve`; it stays
// with another count or where its curve `turns_back`.
void hold_junction(uint32_t p, size_t first, size_t on_curve, const std::array<uint32_t, 2>& curve,
                   bool turns_back, Stencil& stencil, InterfaceFigures& figures) {
  stencil.neighbours.resize(first);
  if (on_curve != 2 || turns_back) {
    ++figures.fixed_points;
    return;
  }
  stencil.neighbours.push_back(curve[0]);
  stencil.neighbours.push_back(curve[1]);
  stencil.along_curve[p] = true;
  ++figures.curve_points;
}

// Two points are neighbours when their cubes share a face whose four voxels
// do not all hold one label: a quad then has both as consecutive corners.
// The six directions in this order give each point's neighbours in
// increasing index, as the points are numbered in cube index order.
// A point where three labels or more meet averages over all its neighbours
// too when two of them or more are such points: on the grids hospitals send,
// where three labels meet is mostly a band, not a curve (a gap of outside one
// voxel wide between two organs, a thin tissue between them), and held to
// its curves the surface kept its staircase there. Only next to a label in
// `small.sharp` is the curve held sharp, as Frisken's nets do: a junction
// point then averages over its two neighbours on the curve, and stays where
// it has another count or, with `fix_turns_back` (on thinner slices, whose
// interpolated labels make such curves), where its curve turns back.
// Anywhere, a junction point with fewer than two junction neighbours (a
// curve's end, a lone cube holding three labels) stays, and so does every
// point next to a label in `small.fixed`.
Stencil smoothing_stencil(const Net& net, const PaddedLabels& labels, const MarkedCubes& cubes,
                          const SmallLabels& small, bool fix_turns_back,
                          InterfaceFigures& figures) {
  constexpr std::array<std::array<int, 2>, 6> kDirections{
      {{2, -1}, {1, -1}, {0, -1}, {0, 1}, {1, 1}, {2, 1}}};  // axis, sign
  const size_t n = net.centre.size();
  Stencil stencil;
  stencil.start.assign(n + 1, 0);
  stencil.neighbours.reserve(4 * n);
  stencil.along_curve.assign(n, false);
  const auto next_to = [&](const std::array<int64_t, 3>& cube, const std::vector<int32_t>& these) {
    return holds_small(corners(labels, cube[0], cube[1], cube[2]), these);
  };
  cubes.for_each_point([&](size_t i, uint32_t p) {
    stencil.start[p] = static_cast<uint32_t>(stencil.neighbours.size());
    const size_t first = stencil.neighbours.size();
    const bool junction = net.label_count[p] > 2;
    const std::array<int64_t, 3> cube = cubes.cube(i);
    // A junction's first two neighbours that are junction points too, and
    // their cubes, for the turn test.
    std::array<std::array<int64_t, 3>, 2> taken{};
    std::array<uint32_t, 2> curve{};
    size_t on_curve = 0;
    for (const auto& [axis, sign] : kDirections) {
      std::array<int64_t, 3> next = cube;
      next[axis] += sign;
      if (next[axis] < 0 || next[axis] >= cubes.dims()[axis]) continue;
      const uint32_t q = cubes.point(cubes.index(next[0], next[1], next[2]));
      if (q == kNoPoint) continue;
      // The shared face's voxels: along `axis` at the far side of
      // whichever cube comes first, both ways along the other two.
      std::array<int64_t, 3> corner = cube;
      corner[axis] += sign > 0 ? 1 : 0;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int32_t label = labels.at(corner[0], corner[1], corner[2]);
      bool uniform = true;
      for (int k = 1; k < 4 && uniform; ++k) {
        std::array<int64_t, 3> other = corner;
        other[u] += k & 1;
        other[v] += k >> 1;
        uniform = labels.at(other[0], other[1], other[2]) == label;
      }
      if (uniform) continue;
      stencil.neighbours.push_back(q);
      if (!junction || net.label_count[q] <= 2) continue;
      if (on_curve < 2) {
        taken[on_curve] = next;
        curve[on_curve] = q;
      }
      ++on_curve;
    }
    if (junction) ++figures.junction_points;
    if (!small.fixed.empty() && next_to(cube, small.fixed)) {
      stencil.neighbours.resize(first);
      ++figures.fixed_points;
      return;
    }
    if (!junction) return;
    if (on_curve >= 2 && !next_to(cube, small.sharp)) return;
    hold_junction(p, first, on_curve, curve,
                  on_curve == 2 && fix_turns_back && turns_back(cube, taken, cubes, net), stencil,
                  figures);
  });
  stencil.start[n] = static_cast<uint32_t>(stencil.neighbours.size());
  return stencil;
}

// The stencil of a net with a point per sheet (Net::first_point): two
// points are neighbours when a quad has both as consecutive corners (as in
// smoothing_stencil, where they share a face whose voxels differ). Junction
// points follow smoothing_stencil's rules, without the turn test (such nets
// are not made on thinner slices), and a point holds its curve (or stays,
// next to a label kept fixed) when such a label is on its own sheet, not
// merely in its cube.
Stencil stencil_from_quads(const Net& net, InterfaceFigures& figures) {
  const size_t n = net.centre.size();
  // Each point's quad neighbours, with repeats (an edge lies on two quads
  // or more): its two neighbours in each of its quads.
  std::vector<uint32_t> offset(n + 1, 0);
  for (const auto& q : net.quads)
    for (const uint32_t p : q) offset[p + 1] += 2;
  for (size_t p = 0; p < n; ++p) offset[p + 1] += offset[p];
  std::vector<uint32_t> around(offset[n]);
  {
    std::vector<uint32_t> filled(offset.begin(), offset.end() - 1);
    for (const auto& q : net.quads) {
      for (int k = 0; k < 4; ++k) {
        around[filled[q[k]]++] = q[(k + 1) % 4];
        around[filled[q[k]]++] = q[(k + 3) % 4];
      }
    }
  }
  Stencil stencil;
  stencil.start.assign(n + 1, 0);
  stencil.neighbours.reserve(around.size() / 2);
  stencil.along_curve.assign(n, false);
  for (size_t p = 0; p < n; ++p) {
    stencil.start[p] = static_cast<uint32_t>(stencil.neighbours.size());
    const size_t first = stencil.neighbours.size();
    std::array<uint32_t, 2> curve{};
    size_t on_curve = 0;
    const auto begin = around.begin() + offset[p];
    const auto end = around.begin() + offset[p + 1];
    std::sort(begin, end);
    const auto last = std::unique(begin, end);
    for (auto it = begin; it != last; ++it) {
      const uint32_t q = *it;
      if (q == p) continue;
      stencil.neighbours.push_back(q);
      if (net.label_count[p] <= 2 || net.label_count[q] <= 2) continue;
      if (on_curve < 2) curve[on_curve] = q;
      ++on_curve;
    }
    if (net.label_count[p] > 2) ++figures.junction_points;
    if (net.near_fixed[p]) {
      stencil.neighbours.resize(first);
      ++figures.fixed_points;
      continue;
    }
    if (net.label_count[p] <= 2) continue;
    if (on_curve >= 2 && !net.near_small[p]) continue;
    hold_junction(static_cast<uint32_t>(p), first, on_curve, curve, /*turns_back=*/false, stencil,
                  figures);
  }
  stencil.start[n] = static_cast<uint32_t>(stencil.neighbours.size());
  return stencil;
}

// On a grid with thicker slices along some axis, a quad is as long as the
// slice along that axis and as short as the pixel along the others: its
// triangles would be needles, and so would the tetrahedra on them. Each quad
// is cut into k_u x k_v smaller ones, k_a being the spacing along axis a over
// the smallest spacing (rounded), with points on shared edges made once.
// `points` and `centre` grow by the new points, bilinear between the
// quad's corners.
void subdivide_quads(const std::array<double, 3>& spacing, Net& net, std::vector<Vec3>& points,
                     std::vector<Vec3>& centre) {
  const double least = std::min({spacing[0], spacing[1], spacing[2]});
  std::array<int, 3> parts{};
  for (int a = 0; a < 3; ++a)
    parts[a] = std::max(1, static_cast<int>(std::lround(spacing[a] / least)));
  if (parts == std::array<int, 3>{1, 1, 1}) return;

  const auto lerp = [](const Vec3& a, const Vec3& b, double t) {
    return geometry::add(a, geometry::scale(geometry::sub(b, a), t));
  };
  const auto add_point = [&](const Vec3& position, const Vec3& on_staircase) {
    points.push_back(position);
    centre.push_back(on_staircase);
    return static_cast<uint32_t>(points.size() - 1);
  };
  // The k - 1 points inside edge (a, b), from a to b, made on first use.
  std::unordered_map<uint64_t, uint32_t> edge_points;
  const auto edge = [&](uint32_t a, uint32_t b, int k, int i) -> uint32_t {
    if (i == 0) return a;
    if (i == k) return b;
    const bool forward = a < b;
    const uint64_t key = forward ? (uint64_t{a} << 32) | b : (uint64_t{b} << 32) | a;
    auto [it, made] = edge_points.try_emplace(key, 0);
    if (made) {
      const uint32_t lo = forward ? a : b, hi = forward ? b : a;
      it->second = static_cast<uint32_t>(points.size());
      for (int j = 1; j < k; ++j) {
        const double t = double(j) / k;
        add_point(lerp(points[lo], points[hi], t), lerp(centre[lo], centre[hi], t));
      }
    }
    return it->second + static_cast<uint32_t>(forward ? i - 1 : k - i - 1);
  };

  std::vector<std::array<uint32_t, 4>> quads;
  std::vector<std::array<int32_t, 2>> sides;
  std::vector<std::array<uint64_t, 2>> voxels;
  for (size_t q = 0; q < net.quads.size(); ++q) {
    const auto& c = net.quads[q];
    const int ku = parts[(net.quad_axis[q] + 1) % 3];
    const int kv = parts[(net.quad_axis[q] + 2) % 3];
    // grid[j][i]: i along u (corner 0 to 1), j along v (corner 0 to 3).
    std::vector<std::vector<uint32_t>> grid(kv + 1, std::vector<uint32_t>(ku + 1));
    for (int i = 0; i <= ku; ++i) {
      grid[0][i] = edge(c[0], c[1], ku, i);
      grid[kv][i] = edge(c[3], c[2], ku, i);
    }
    for (int j = 1; j < kv; ++j) {
      grid[j][0] = edge(c[0], c[3], kv, j);
      grid[j][ku] = edge(c[1], c[2], kv, j);
      for (int i = 1; i < ku; ++i) {
        const double u = double(i) / ku;
        grid[j][i] = add_point(lerp(points[grid[j][0]], points[grid[j][ku]], u),
                               lerp(centre[grid[j][0]], centre[grid[j][ku]], u));
      }
    }
    for (int j = 0; j < kv; ++j) {
      for (int i = 0; i < ku; ++i) {
        quads.push_back({grid[j][i], grid[j][i + 1], grid[j + 1][i + 1], grid[j + 1][i]});
        sides.push_back(net.quad_sides[q]);
        voxels.push_back(net.quad_voxels[q]);
      }
    }
  }
  net.quads = std::move(quads);
  net.quad_sides = std::move(sides);
  net.quad_voxels = std::move(voxels);
  net.quad_axis.clear();
}

}  // namespace

InterfaceSurface label_interfaces(const volume::LabelVolume& volume,
                                  const std::vector<int32_t>& labels, const InterfaceParams& params,
                                  InterfaceFigures& figures) {
  const auto start = std::chrono::steady_clock::now();
  figures = InterfaceFigures{};
  const auto& geometry = volume.geometry;
  PaddedLabels padded = padded_labels(volume, labels);
  MarkedCubes cubes({padded.dims[0] - 1, padded.dims[1] - 1, padded.dims[2] - 1});
  Net net;
  Stencil stencil;
  {
    const auto pairs = differing_pairs(padded);
    // Without smoothing the stencil only matters for widening.
    const auto find_small = [&] {
      return params.smoothing_rounds > 0 || params.widen_angles_below_deg > 0
                 ? small_labels(padded, params.drawn_axis >= 0 ? params.drawn_parts : 1)
                 : SmallLabels{};
    };
    const bool split = params.split_sheets && params.drawn_axis < 0;
    net = net_points(padded, geometry.spacing, pairs, cubes, split,
                     split ? find_small() : SmallLabels{}, geometry.dims, params.joined_voxels);
    // On one point per cube the quads and the smoothing stencil only read
    // the numbered cubes and write apart: they are made side by side. The
    // quads' arrays are reserved here, so that they belong to this thread's
    // heap (glibc keeps one per thread, and memory freed in another thread's
    // is not reused here).
    net.quads.reserve(pairs.size());
    net.quad_sides.reserve(pairs.size());
    net.quad_axis.reserve(pairs.size());
    net.quad_voxels.reserve(pairs.size());
    if (split) {
      add_quads(padded, pairs, cubes, net);
      stencil = stencil_from_quads(net, figures);
    } else {
      side_by_side([&] { add_quads(padded, pairs, cubes, net); },
                   [&] {
                     stencil = smoothing_stencil(net, padded, cubes, find_small(),
                                                 params.drawn_axis >= 0, figures);
                   });
    }
  }
  // The labels are not read again: their memory goes before smoothing's.
  std::vector<int32_t>().swap(padded.labels);

  const double half = 0.5 * params.cube_fraction;
  PointBoxes boxes = point_boxes(geometry, params);
  if (boxes.drawn_axis >= 0) {
    boxes.narrow.resize(net.label_count.size());
    for (size_t p = 0; p < net.label_count.size(); ++p) boxes.narrow[p] = net.label_count[p] > 2;
  }
  hold_at_edges(net.centre, geometry, boxes);
  if (params.follow_cap_rims) figures.rim_points = follow_cap_rims(boxes, net.label_count, stencil);
  std::vector<Vec3> points = net.centre;
  if (params.restore_volumes) {
    const LabelVolumeKeeper keeper = [&] {
      // Points the stencil holds still stay.
      std::vector<bool> held(points.size());
      for (size_t p = 0; p < points.size(); ++p) held[p] = stencil.start[p] == stencil.start[p + 1];
      return LabelVolumeKeeper(net.quads, net.quad_sides, held, net.centre);
    }();
    // The rounds in pieces, one round of the volume step between them and
    // all of its rounds after the last; no piece without rounds.
    const int pieces =
        std::clamp(params.smoothing_rounds, 1, std::max(1, params.volume_pauses + 1));
    for (int k = 0; k < pieces; ++k) {
      const int rounds =
          params.smoothing_rounds * (k + 1) / pieces - params.smoothing_rounds * k / pieces;
      smooth_in_boxes(stencil, net.centre, boxes, params, rounds, points);
      keeper.restore(boxes, k + 1 < pieces ? 1 : kVolumeRounds, points);
    }
  } else {
    smooth_in_boxes(stencil, net.centre, boxes, params, params.smoothing_rounds, points);
  }
  std::vector<Vec3> before_widening;
  // Widened nets keep two triangles per quad (the take-back splits quads
  // again), so a net cut into smaller quads is not widened.
  if (params.widen_angles_below_deg > 0 && !params.subdivide_thick_quads) {
    before_widening = points;
    // Points of a junction curve held sharp slide along it; fixed points stay.
    std::vector<Slide> slides(points.size());
    for (size_t p = 0; p < points.size(); ++p) {
      const uint32_t first = stencil.start[p], last = stencil.start[p + 1];
      if (first == last) continue;
      if (!stencil.along_curve[p]) {
        slides[p].kind = Slide::Kind::kSurface;
      } else {
        slides[p].kind = Slide::Kind::kCurve;
        slides[p].curve = {stencil.neighbours[first], stencil.neighbours[first + 1]};
      }
    }
    // Across the surface by about a quarter of the grid's own voxel.
    const Vec3 across{0.5 * half * geometry.spacing[0], 0.5 * half * geometry.spacing[1],
                      0.5 * half * geometry.spacing[2]};
    // A cap's points may leave its plane inwards where that widens a thin
    // triangle at its rim (they still stay within the edges).
    PointBoxes sliding = boxes;
    std::vector<uint8_t>().swap(sliding.pinned);
    const auto widened = widen_small_angles(
        net.quads, net.quad_sides, slides, net.centre, sliding, across,
        {.below_deg = params.widen_angles_below_deg, .far_below_deg = params.widen_far_below_deg},
        points);
    figures.widened_points = widened.points_moved;
  }
  if (params.subdivide_thick_quads) subdivide_quads(geometry.spacing, net, points, net.centre);

  InterfaceSurface surface;
  const auto to_patient = [&](const Vec3& scaled) {
    return geometry.to_physical({scaled[0] / geometry.spacing[0], scaled[1] / geometry.spacing[1],
                                 scaled[2] / geometry.spacing[2]});
  };
  surface.points.resize(points.size());
  surface.staircase.resize(points.size());
  in_two_halves(points.size(), [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      surface.points[p] = to_patient(points[p]);
      surface.staircase[p] = to_patient(net.centre[p]);
    }
  });
  for (size_t p = 0; p < points.size(); ++p) {
    figures.max_offset_mm =
        std::max(figures.max_offset_mm,
                 geometry::norm(geometry::sub(surface.points[p], surface.staircase[p])));
  }
  for (size_t p = 0; p < before_widening.size(); ++p)
    if (before_widening[p] != points[p])
      surface.widened.push_back({static_cast<uint32_t>(p), to_patient(before_widening[p])});

  // A direction matrix with negative determinant mirrors space: windings
  // reverse so that normals still point from sides[0] to sides[1].
  const auto& d = geometry.direction;
  const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                     d[2] * (d[3] * d[7] - d[4] * d[6]);
  const bool mirrored = det < 0;
  surface.triangles.resize(2 * net.quads.size());
  surface.sides.resize(2 * net.quads.size());
  surface.side_voxels.resize(2 * net.quads.size());
  surface.padded_dims = padded.dims;
  surface.padded_first = padded.first;
  in_two_halves(net.quads.size(), [&](size_t begin, size_t end) {
    for (size_t q = begin; q < end; ++q) {
      const auto& quad = net.quads[q];
      std::array<std::array<uint32_t, 3>, 2> pair =
          best_quad_split(quad, surface.points).along_02
              ? std::array<std::array<uint32_t, 3>, 2>{{{quad[0], quad[1], quad[2]},
                                                        {quad[0], quad[2], quad[3]}}}
              : std::array<std::array<uint32_t, 3>, 2>{
                    {{quad[0], quad[1], quad[3]}, {quad[1], quad[2], quad[3]}}};
      for (size_t k = 0; k < 2; ++k) {
        auto& triangle = pair[k];
        if (mirrored) std::swap(triangle[1], triangle[2]);
        surface.triangles[2 * q + k] = triangle;
        surface.sides[2 * q + k] = net.quad_sides[q];
        surface.side_voxels[2 * q + k] = net.quad_voxels[q];
      }
    }
  });
  figures.points = surface.points.size();
  figures.triangles = surface.triangles.size();
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return surface;
}

void restore_staircase(InterfaceSurface& surface, const std::vector<uint32_t>& points) {
  std::vector<bool> restored(surface.points.size(), false);
  for (uint32_t p : points) {
    surface.points[p] = surface.staircase[p];
    restored[p] = true;
  }
  auto& widened = surface.widened;
  widened.erase(std::remove_if(widened.begin(), widened.end(),
                               [&](const auto& slid) { return restored[slid.point]; }),
                widened.end());
}

}  // namespace labelmesh::conforming
