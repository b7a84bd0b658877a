// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/octree_core.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/mixed_mesh/mixed_faces.h"
#include "core/util/text.h"

namespace labelmesh::mixed_mesh {
namespace {

using Index = std::array<int64_t, 3>;
using Point = std::array<double, 3>;

// VTK_HEXAHEDRON's corners as offsets from the lowest one.
constexpr std::array<Index, 8> kCorners{
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                               {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
constexpr int kLevels = 8;

Index mid(const Index& a, const Index& b) {
  return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

// Node coordinates fit 21 bits each: the core's grid is at most 2^28 cubes.
uint64_t key(const Index& v) {
  return uint64_t(v[0]) | uint64_t(v[1]) << 21 | uint64_t(v[2]) << 42;
}

// Cells for a set of octants: a hexahedron each, or a transition pattern
// about its centre where a finer neighbour leaves hanging nodes.
class OctantMesher {
 public:
  OctantMesher(const Point& origin, double cell_mm, int32_t label, OctreeFigures& figures)
      : origin_(origin), h_(cell_mm), label_(label), figures_(figures) {}

  MixedMesh mesh(const std::vector<Octant>& octants) {
    for (const Octant& o : octants) {
      const int64_t size = int64_t{1} << o.level;
      for (const Index& corner : kCorners)
        corners_.insert(key({o.anchor[0] + size * corner[0], o.anchor[1] + size * corner[1],
                             o.anchor[2] + size * corner[2]}));
      ++figures_.octants[o.level];
    }
    for (const Octant& o : octants) emit_octant(o.anchor, o.level);
    return std::move(mesh_);
  }

 private:
  uint32_t node(const Index& v) {
    const auto [found, added] = nodes_.emplace(key(v), uint32_t(mesh_.points.size()));
    if (added) {
      mesh_.points.push_back({origin_[0] + double(v[0]) * h_, origin_[1] + double(v[1]) * h_,
                              origin_[2] + double(v[2]) * h_});
    }
    return found->second;
  }
  bool is_corner(const Index& v) const { return corners_.count(key(v)) > 0; }

  void emit_octant(const Index& anchor, int level) {
    const int64_t size = int64_t{1} << level;
    std::array<Index, 8> c;
    for (int k = 0; k < 8; ++k)
      for (int a = 0; a < 3; ++a) c[k][a] = anchor[a] + size * kCorners[k][a];
    bool hanging = false;
    if (level > 0) {
      for (const auto& e : kEdges) hanging |= is_corner(mid(c[e[0]], c[e[1]]));
      for (int f = 0; f < 6; ++f) {
        const auto face = hexahedron_face_inward(f);
        hanging |= is_corner(mid(c[face[0]], c[face[2]]));
      }
    }
    if (!hanging) {
      std::array<uint32_t, 8> hex{};
      for (int k = 0; k < 8; ++k) hex[k] = node(c[k]);
      mesh_.add(CellType::kHexahedron, hex, label_);
      return;
    }
    ++figures_.transition_octants;
    const uint32_t centre = node(mid(c[0], c[6]));
    for (int f = 0; f < 6; ++f) {
      const auto face = hexahedron_face_inward(f);
      const std::array<Index, 4> b{c[face[0]], c[face[1]], c[face[2]], c[face[3]]};
      const Index face_centre = mid(b[0], b[2]);
      std::array<Index, 4> m;
      for (int k = 0; k < 4; ++k) m[k] = mid(b[k], b[(k + 1) % 4]);
      if (is_corner(face_centre)) {
        // The finer neighbour's four squares, each a pyramid.
        const std::array<std::array<Index, 4>, 4> quarters{{{b[0], m[0], face_centre, m[3]},
                                                            {m[0], b[1], m[1], face_centre},
                                                            {face_centre, m[1], b[2], m[2]},
                                                            {m[3], face_centre, m[2], b[3]}}};
        for (const auto& q : quarters)
          mesh_.add(CellType::kPyramid, {node(q[0]), node(q[1]), node(q[2]), node(q[3]), centre},
                    label_);
        continue;
      }
      std::vector<uint32_t> ring;
      for (int k = 0; k < 4; ++k) {
        ring.push_back(node(b[k]));
        if (is_corner(m[k])) ring.push_back(node(m[k]));
      }
      if (ring.size() == 4) {
        mesh_.add(CellType::kPyramid, {ring[0], ring[1], ring[2], ring[3], centre}, label_);
        continue;
      }
      // Edge midpoints only: triangles fanned from the face's centre, which
      // the octant across the face makes the same way.
      const uint32_t fan = node(face_centre);
      for (size_t k = 0; k < ring.size(); ++k)
        mesh_.add(CellType::kTetra, {fan, ring[k], ring[(k + 1) % ring.size()], centre}, label_);
    }
  }

  Point origin_;
  double h_;
  int32_t label_;
  OctreeFigures& figures_;
  std::unordered_set<uint64_t> corners_;
  std::unordered_map<uint64_t, uint32_t> nodes_;
  MixedMesh mesh_;
};

class Octree {
 public:
  Octree(const OctreeParams& params, OctreeFigures& figures) : params_(params), figures_(figures) {}

  // The core's cubes on their grid; false when a cube is off it.
  bool read(const MixedMesh& core) {
    origin_ = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
               std::numeric_limits<double>::max()};
    for (const auto& p : core.points)
      for (int a = 0; a < 3; ++a) origin_[a] = std::min(origin_[a], p[a]);
    const double h = params_.cell_mm;
    std::vector<Index> cubes;
    for (size_t c = 0; c < core.size(); ++c) {
      const Point& low = core.points[core.cells[c][0]];
      const Point& high = core.points[core.cells[c][6]];
      Index at{};
      for (int a = 0; a < 3; ++a) {
        const double steps = (low[a] - origin_[a]) / h;
        at[a] = std::llround(steps);
        if (std::abs(steps - double(at[a])) > 1e-6 || std::abs(high[a] - low[a] - h) > 1e-6 * h)
          return false;
        n_[a] = std::max(n_[a], at[a] + 1);
      }
      cubes.push_back(at);
    }
    if (n_[0] >= (1 << 20) || n_[1] >= (1 << 20) || n_[2] >= (1 << 20)) return false;
    level_.assign(size_t(n_[0] * n_[1] * n_[2]), -1);
    for (const Index& at : cubes) level_[cell(at)] = 0;
    label_ = core.labels.empty() ? 0 : core.labels.front();
    return true;
  }

  // Chessboard distance of each core cube to the nearest cube with a
  // neighbour outside the core (those are at 0).
  void measure_depths() {
    depth_.assign(level_.size(), -1);
    std::deque<Index> queue;
    for_each_cube([&](const Index& at) {
      bool outer = false;
      for_each_neighbour(at, [&](const Index& next) { outer |= !in_core(next); });
      if (outer) {
        depth_[cell(at)] = 0;
        queue.push_back(at);
      }
    });
    while (!queue.empty()) {
      const Index at = queue.front();
      queue.pop_front();
      for_each_neighbour(at, [&](const Index& next) {
        if (in_core(next) && depth_[cell(next)] < 0) {
          depth_[cell(next)] = depth_[cell(at)] + 1;
          queue.push_back(next);
        }
      });
    }
  }

  // Merges blocks of eight octants, level by level, where they lie deep
  // enough: a ring of each finer level fits between them and the boundary.
  void coarsen() {
    const double ratio = params_.interior_mm / params_.cell_mm;
    int top = 0;
    while (top + 1 < kLevels && double(int64_t{1} << (top + 1)) <= ratio + 1e-9) ++top;
    for (int level = 1; level <= top; ++level) {
      const int64_t size = int64_t{1} << level;
      const int64_t least_depth = params_.surface_layers + size - 2;
      for (int64_t z = 0; z + size <= n_[2]; z += size)
        for (int64_t y = 0; y + size <= n_[1]; y += size)
          for (int64_t x = 0; x + size <= n_[0]; x += size) {
            bool merge = true;
            for_block({x, y, z}, size, [&](const Index& at) {
              merge &= level_[cell(at)] == level - 1 && depth_[cell(at)] >= least_depth;
            });
            if (merge)
              for_block({x, y, z}, size,
                        [&](const Index& at) { level_[cell(at)] = int8_t(level); });
          }
    }
  }

  // Splits octants with a neighbour (across a face, an edge or a corner) two
  // or more levels finer, until none is left.
  void balance() {
    for (bool split = true; split;) {
      split = false;
      for_each_octant([&](const Index& anchor, int level) {
        if (level < 2) return;
        const int64_t size = int64_t{1} << level;
        bool too_coarse = false;
        for (int64_t z = anchor[2] - 1; z <= anchor[2] + size && !too_coarse; ++z)
          for (int64_t y = anchor[1] - 1; y <= anchor[1] + size && !too_coarse; ++y)
            for (int64_t x = anchor[0] - 1; x <= anchor[0] + size && !too_coarse; ++x) {
              const bool inside = x >= anchor[0] && x < anchor[0] + size && y >= anchor[1] &&
                                  y < anchor[1] + size && z >= anchor[2] && z < anchor[2] + size;
              if (inside || !in_core({x, y, z})) continue;
              too_coarse = level_[cell({x, y, z})] < level - 1;
            }
        if (!too_coarse) return;
        for_block(anchor, size, [&](const Index& at) { level_[cell(at)] = int8_t(level - 1); });
        ++figures_.balance_splits;
        split = true;
      });
    }
  }

  MixedMesh emit() {
    std::vector<Octant> octants;
    for_each_octant([&](const Index& anchor, int level) { octants.push_back({anchor, level}); });
    return mesh_octants(octants, origin_, params_.cell_mm, label_, figures_);
  }

 private:
  int64_t cell(const Index& at) const { return (at[2] * n_[1] + at[1]) * n_[0] + at[0]; }
  bool in_grid(const Index& at) const {
    return at[0] >= 0 && at[1] >= 0 && at[2] >= 0 && at[0] < n_[0] && at[1] < n_[1] &&
           at[2] < n_[2];
  }
  bool in_core(const Index& at) const { return in_grid(at) && level_[cell(at)] >= 0; }

  template <typename F>
  void for_each_cube(F&& f) const {
    for (int64_t z = 0; z < n_[2]; ++z)
      for (int64_t y = 0; y < n_[1]; ++y)
        for (int64_t x = 0; x < n_[0]; ++x)
          if (level_[cell({x, y, z})] >= 0) f(Index{x, y, z});
  }
  template <typename F>
  void for_each_neighbour(const Index& at, F&& f) const {
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx)
          if (dx || dy || dz) f(Index{at[0] + dx, at[1] + dy, at[2] + dz});
  }
  template <typename F>
  void for_block(const Index& anchor, int64_t size, F&& f) const {
    for (int64_t z = anchor[2]; z < anchor[2] + size; ++z)
      for (int64_t y = anchor[1]; y < anchor[1] + size; ++y)
        for (int64_t x = anchor[0]; x < anchor[0] + size; ++x) f(Index{x, y, z});
  }
  // Each octant once, at its lowest cube.
  template <typename F>
  void for_each_octant(F&& f) const {
    for_each_cube([&](const Index& at) {
      const int level = level_[cell(at)];
      const int64_t mask = (int64_t{1} << level) - 1;
      if ((at[0] & mask) == 0 && (at[1] & mask) == 0 && (at[2] & mask) == 0) f(at, level);
    });
  }

  const OctreeParams& params_;
  OctreeFigures& figures_;
  Point origin_{};
  Index n_{0, 0, 0};
  int32_t label_ = 0;
  std::vector<int8_t> level_;  // per cube: its octant's level, -1 outside the core
  std::vector<int32_t> depth_;
};

}  // namespace

MixedMesh mesh_octants(const std::vector<Octant>& octants, const std::array<double, 3>& origin,
                       double cell_mm, int32_t label, OctreeFigures& figures) {
  return OctantMesher(origin, cell_mm, label, figures).mesh(octants);
}

absl::StatusOr<MixedMesh> coarsen_core(const MixedMesh& core, const OctreeParams& params,
                                       OctreeFigures& figures) {
  for (CellType type : core.types) {
    if (type != CellType::kHexahedron)
      return absl::InvalidArgumentError("octree: the core holds cells other than hexahedra");
  }
  if (!(params.cell_mm > 0) || !(params.surface_layers >= 1))
    return absl::InvalidArgumentError(
        cat("octree: cell ", params.cell_mm, " mm, ", params.surface_layers, " surface layers"));
  if (core.size() == 0 || !(params.interior_mm >= 2 * params.cell_mm)) {
    figures.octants[0] = core.size();
    return core;
  }
  Octree octree(params, figures);
  if (!octree.read(core)) return absl::InvalidArgumentError("octree: a core cube is off the grid");
  octree.measure_depths();
  octree.coarsen();
  octree.balance();
  return octree.emit();
}

}  // namespace labelmesh::mixed_mesh
