// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/hex_core.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::mixed_mesh {
namespace {

using Point = std::array<double, 3>;
using Index = std::array<int64_t, 3>;

// Cubes of edge h covering the surface's bounding box.
struct Grid {
  Point origin{};
  double h = 1;
  Index n{0, 0, 0};

  int64_t cells() const { return n[0] * n[1] * n[2]; }
  bool inside(const Index& c) const {
    return c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < n[0] && c[1] < n[1] && c[2] < n[2];
  }
  int64_t cell(const Index& c) const { return (c[2] * n[1] + c[1]) * n[0] + c[0]; }
  Index index(int64_t cell) const {
    return {cell % n[0], (cell / n[0]) % n[1], cell / (n[0] * n[1])};
  }
  int64_t node(const Index& v) const { return (v[2] * (n[1] + 1) + v[1]) * (n[0] + 1) + v[0]; }
  Point node_point(const Index& v) const {
    return {origin[0] + double(v[0]) * h, origin[1] + double(v[1]) * h,
            origin[2] + double(v[2]) * h};
  }
  Point centre(const Index& c) const {
    return {origin[0] + (double(c[0]) + 0.5) * h, origin[1] + (double(c[1]) + 0.5) * h,
            origin[2] + (double(c[2]) + 0.5) * h};
  }
};

Grid make_grid(const surface::TriangleMesh& surface, double h) {
  Grid grid;
  grid.h = h;
  Point lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
           std::numeric_limits<double>::max()};
  Point hi{-lo[0], -lo[1], -lo[2]};
  for (const auto& p : surface.points) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  if (surface.points.empty()) return grid;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = lo[a];
    // Capped so that the cast cannot overflow; the caller refuses such grids.
    grid.n[a] = static_cast<int64_t>(std::min(std::ceil((hi[a] - lo[a]) / h), 1e12));
  }
  return grid;
}

double distance(const Point& a, const Point& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// The six faces of a cube, as the outward axis direction and the corners
// (offsets from the cell's lowest node) counter-clockwise seen from outside.
struct Face {
  Index direction;
  std::array<Index, 4> corners;
};
constexpr std::array<Face, 6> kFaces{{
    {{1, 0, 0}, {{{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}}},
    {{-1, 0, 0}, {{{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}}},
    {{0, 1, 0}, {{{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}}},
    {{0, -1, 0}, {{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}}},
    {{0, 0, 1}, {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}}},
    {{0, 0, -1}, {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}}},
}};
// VTK_HEXAHEDRON: the bottom face counter-clockwise seen from above, then the top.
constexpr std::array<Index, 8> kHexCorners{
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

Index plus(const Index& a, const Index& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

// manifold[mask]: the 8 cubes around a node, bit dx + 2 dy + 4 dz set for
// core cubes, leave the core's boundary a disc there: the core cubes and the
// others each face-connected within the 2x2x2 block (or one set empty).
std::array<bool, 256> manifold_table() {
  std::array<bool, 256> table{};
  auto connected = [](int set) {
    if (set == 0) return true;
    int reached = set & -set;
    for (bool grew = true; grew;) {
      grew = false;
      for (int b = 0; b < 8; ++b) {
        if (!(reached >> b & 1)) continue;
        for (int axis = 0; axis < 3; ++axis) {
          const int neighbour = b ^ (1 << axis);
          if ((set >> neighbour & 1) && !(reached >> neighbour & 1)) {
            reached |= 1 << neighbour;
            grew = true;
          }
        }
      }
    }
    return reached == set;
  };
  for (int mask = 0; mask < 256; ++mask) table[mask] = connected(mask) && connected(255 & ~mask);
  return table;
}

class CoreBuilder {
 public:
  CoreBuilder(const SurfaceOracle& oracle, const Grid& grid, const HexCoreParams& params,
              const RunContext& context)
      : oracle_(oracle), grid_(grid), params_(params), context_(context) {
    const double h = grid.h;
    cell_depth_ = (std::sqrt(3.0) / 2 + params.margin) * h;
    face_depth_ = (std::max(1 / std::sqrt(2.0), params.apex_height) + params.margin) * h;
    // A cube this deep passes every face test: its faces' centres are h/2 closer.
    sure_depth_ = face_depth_ + h / 2;
  }

  absl::Status classify(HexCore& core) {
    depth_.assign(static_cast<size_t>(grid_.cells()), -std::numeric_limits<float>::infinity());
    constexpr int64_t kBlock = 4;
    struct Block {
      Index lo, hi;  // cells [lo, hi)
      Point centre;
      double radius;
    };
    std::vector<Block> blocks;
    for (int64_t k = 0; k < grid_.n[2]; k += kBlock)
      for (int64_t j = 0; j < grid_.n[1]; j += kBlock)
        for (int64_t i = 0; i < grid_.n[0]; i += kBlock) {
          Block b;
          b.lo = {i, j, k};
          b.hi = {std::min(i + kBlock, grid_.n[0]), std::min(j + kBlock, grid_.n[1]),
                  std::min(k + kBlock, grid_.n[2])};
          const Point first = grid_.centre(b.lo);
          const Point last = grid_.centre({b.hi[0] - 1, b.hi[1] - 1, b.hi[2] - 1});
          for (int a = 0; a < 3; ++a) b.centre[a] = (first[a] + last[a]) / 2;
          b.radius = distance(first, last) / 2;
          blocks.push_back(b);
        }
    std::vector<Point> centres;
    for (const auto& b : blocks) centres.push_back(b.centre);
    const auto block_depths = oracle_.depths(centres, params_.threads);
    core.depth_queries += centres.size();
    LABELMESH_RETURN_IF_ERROR(context_.check_stop());
    // Depth is 1-Lipschitz: a block's centre bounds every cube in it.
    std::vector<int64_t> exact;
    for (size_t b = 0; b < blocks.size(); ++b) {
      const Block& block = blocks[b];
      const double d = block_depths[b];
      if (d + block.radius < cell_depth_) continue;
      for (int64_t k = block.lo[2]; k < block.hi[2]; ++k)
        for (int64_t j = block.lo[1]; j < block.hi[1]; ++j)
          for (int64_t i = block.lo[0]; i < block.hi[0]; ++i) {
            const Index c{i, j, k};
            if (d - block.radius >= sure_depth_) {
              depth_[grid_.cell(c)] =
                  static_cast<float>(d - distance(block.centre, grid_.centre(c)));
            } else {
              exact.push_back(grid_.cell(c));
            }
          }
    }
    std::vector<Point> points;
    for (int64_t c : exact) points.push_back(grid_.centre(grid_.index(c)));
    const auto depths = oracle_.depths(points, params_.threads);
    core.depth_queries += points.size();
    for (size_t e = 0; e < exact.size(); ++e) depth_[exact[e]] = static_cast<float>(depths[e]);
    in_core_.assign(depth_.size(), 0);
    for (size_t c = 0; c < depth_.size(); ++c) in_core_[c] = depth_[c] >= cell_depth_;
    return context_.check_stop();
  }

  // Takes cubes out until the core's boundary is a manifold with room for
  // its pyramids.
  absl::Status trim(HexCore& core) {
    static const std::array<bool, 256> manifold = manifold_table();
    for (;;) {
      LABELMESH_RETURN_IF_ERROR(context_.check_stop());
      std::vector<int64_t> remove;
      auto take_shallowest = [&](const std::vector<int64_t>& cells) {
        int64_t shallowest = -1;
        for (int64_t c : cells)
          if (shallowest < 0 || depth_[c] < depth_[shallowest]) shallowest = c;
        if (shallowest >= 0) remove.push_back(shallowest);
      };
      for (int64_t c = 0; c < grid_.cells(); ++c) {
        if (!in_core_[c]) continue;
        const Index cell = grid_.index(c);
        if (!on_boundary(cell)) continue;
        int open_faces = 0;
        for (const Face& face : kFaces) open_faces += !core_at(plus(cell, face.direction));
        if (open_faces > params_.max_open_faces) {
          remove.push_back(c);
          continue;
        }
        if (params_.pyramids && depth_[c] < sure_depth_) {
          for (int f = 0; f < 6; ++f) {
            if (core_at(plus(cell, kFaces[f].direction))) continue;
            if (!pyramid_fits(c, cell, f, core)) {
              remove.push_back(c);
              break;
            }
          }
        }
        // The cube's 8 corners: the cubes around each.
        for (const Index& corner : kHexCorners) {
          const Index v = plus(cell, corner);
          int mask = 0;
          std::vector<int64_t> cells;
          for (int b = 0; b < 8; ++b) {
            const Index around{v[0] - 1 + (b & 1), v[1] - 1 + (b >> 1 & 1),
                               v[2] - 1 + (b >> 2 & 1)};
            if (!core_at(around)) continue;
            mask |= 1 << b;
            cells.push_back(grid_.cell(around));
          }
          if (!manifold[mask]) take_shallowest(cells);
        }
        // The cube's 12 edges: the 4 cubes around each, in turn.
        for (int axis = 0; axis < 3; ++axis) {
          const int u = (axis + 1) % 3, w = (axis + 2) % 3;
          for (int eu = 0; eu < 2; ++eu)
            for (int ew = 0; ew < 2; ++ew) {
              std::array<Index, 4> around;
              const int du[4] = {-1, 0, 0, -1}, dw[4] = {-1, -1, 0, 0};
              std::array<bool, 4> in{};
              for (int q = 0; q < 4; ++q) {
                around[q] = cell;
                around[q][u] += eu + du[q];
                around[q][w] += ew + dw[q];
                in[q] = core_at(around[q]);
              }
              if (in[0] == in[2] && in[1] == in[3] && in[0] != in[1]) {
                std::vector<int64_t> cells;
                for (int q = 0; q < 4; ++q)
                  if (in[q]) cells.push_back(grid_.cell(around[q]));
                take_shallowest(cells);
              }
            }
        }
      }
      std::sort(remove.begin(), remove.end());
      remove.erase(std::unique(remove.begin(), remove.end()), remove.end());
      if (remove.empty()) return absl::OkStatus();
      for (int64_t c : remove) in_core_[c] = 0;
      core.cells_removed += remove.size();
    }
  }

  // The centre of one cube of each face-connected piece of the core.
  void find_cavities(HexCore& core) const {
    std::vector<uint8_t> seen(in_core_.size(), 0);
    std::vector<int64_t> stack;
    for (int64_t c = 0; c < grid_.cells(); ++c) {
      if (!in_core_[c] || seen[c]) continue;
      core.cavity_points.push_back(grid_.centre(grid_.index(c)));
      seen[c] = 1;
      stack.push_back(c);
      while (!stack.empty()) {
        const Index cell = grid_.index(stack.back());
        stack.pop_back();
        for (const Face& face : kFaces) {
          const Index next = plus(cell, face.direction);
          if (!core_at(next) || seen[grid_.cell(next)]) continue;
          seen[grid_.cell(next)] = 1;
          stack.push_back(grid_.cell(next));
        }
      }
    }
  }

  void emit(int32_t label, HexCore& core) const {
    const double h = grid_.h;
    std::vector<int32_t> node_id(
        static_cast<size_t>((grid_.n[0] + 1) * (grid_.n[1] + 1) * (grid_.n[2] + 1)), -1);
    auto node = [&](const Index& v) {
      int32_t& id = node_id[grid_.node(v)];
      if (id < 0) {
        id = static_cast<int32_t>(core.mesh.points.size());
        core.mesh.points.push_back(grid_.node_point(v));
      }
      return static_cast<uint32_t>(id);
    };
    for (int64_t c = 0; c < grid_.cells(); ++c) {
      if (!in_core_[c]) continue;
      const Index cell = grid_.index(c);
      std::array<uint32_t, 8> hex{};
      for (int k = 0; k < 8; ++k) hex[k] = node(plus(cell, kHexCorners[k]));
      core.mesh.add(CellType::kHexahedron, hex, label);
      if (!params_.pyramids) continue;
      for (const Face& face : kFaces) {
        if (core_at(plus(cell, face.direction))) continue;
        std::array<uint32_t, 8> pyramid{};
        for (int k = 0; k < 4; ++k) pyramid[k] = node(plus(cell, face.corners[k]));
        Point apex = grid_.centre(cell);
        for (int a = 0; a < 3; ++a)
          apex[a] += double(face.direction[a]) * (0.5 + params_.apex_height) * h;
        pyramid[4] = static_cast<uint32_t>(core.mesh.points.size());
        core.mesh.points.push_back(apex);
        core.mesh.add(CellType::kPyramid, pyramid, label);
        // Side triangles wound towards the pyramid (and the core behind it).
        for (int k = 0; k < 4; ++k)
          core.shell.push_back({pyramid[(k + 1) % 4], pyramid[k], pyramid[4]});
      }
    }
  }

 private:
  bool core_at(const Index& c) const { return grid_.inside(c) && in_core_[grid_.cell(c)]; }

  bool on_boundary(const Index& cell) const {
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx)
          if (!core_at({cell[0] + dx, cell[1] + dy, cell[2] + dz})) return true;
    return false;
  }

  // The pyramid on face f lies within max(h/√2, apex) of the face's centre:
  // with the margin, inside when the centre is that deep.
  bool pyramid_fits(int64_t c, const Index& cell, int f, HexCore& core) {
    const uint64_t key = uint64_t(c) * 6 + uint64_t(f);
    if (const auto found = face_fits_.find(key); found != face_fits_.end()) return found->second;
    Point centre = grid_.centre(cell);
    for (int a = 0; a < 3; ++a) centre[a] += double(kFaces[f].direction[a]) * grid_.h / 2;
    ++core.depth_queries;
    const bool fits = oracle_.depth(centre) >= face_depth_;
    face_fits_.emplace(key, fits);
    return fits;
  }

  const SurfaceOracle& oracle_;
  const Grid& grid_;
  const HexCoreParams& params_;
  const RunContext& context_;
  double cell_depth_ = 0, face_depth_ = 0, sure_depth_ = 0;
  std::vector<float> depth_;
  std::vector<uint8_t> in_core_;
  std::unordered_map<uint64_t, bool> face_fits_;
};

}  // namespace

absl::StatusOr<HexCore> build_hex_core(const SurfaceOracle& oracle,
                                       const surface::TriangleMesh& surface, int32_t label,
                                       const HexCoreParams& params, const RunContext& context) {
  // At half the edge the apexes of two pyramids meeting at a concave edge coincide.
  if (!(params.cell_mm > 0) || !(params.apex_height > 0 && params.apex_height <= 0.45) ||
      !(params.margin >= 0 && params.margin <= 1)) {
    return absl::InvalidArgumentError(cat("hex core: cell ", params.cell_mm, " mm, apex ",
                                          params.apex_height, ", margin ", params.margin,
                                          " out of range"));
  }
  // About 10 bytes a cube; node ids are 32-bit.
  constexpr int64_t kMostCells = int64_t{1} << 28;
  for (const auto& p : surface.points) {
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(p[a]))
        return absl::InvalidArgumentError("hex core: a surface point is not finite");
    }
  }
  const Grid grid = make_grid(surface, params.cell_mm);
  if (grid.n[0] > kMostCells || grid.n[1] > kMostCells || grid.n[2] > kMostCells ||
      grid.n[0] * grid.n[1] > kMostCells || grid.n[0] * grid.n[1] * grid.n[2] > kMostCells) {
    return absl::InvalidArgumentError(cat(
        "hex core: ", params.cell_mm, " mm cubes over the surface's bounding box make more than ",
        kMostCells, " cells; choose larger ones"));
  }
  HexCore core;
  core.grid_cells = static_cast<uint64_t>(grid.cells());
  if (grid.cells() == 0) return core;
  CoreBuilder builder(oracle, grid, params, context);
  LABELMESH_RETURN_IF_ERROR(builder.classify(core));
  LABELMESH_RETURN_IF_ERROR(builder.trim(core));
  builder.emit(label, core);
  builder.find_cavities(core);
  return core;
}

}  // namespace labelmesh::mixed_mesh
