// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/hex_layer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/mixed_faces.h"
#include "core/quality/element_quality.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/vec3.h"

namespace labelmesh::mixed_mesh {
namespace {

using Point = std::array<double, 3>;
using geometry::add;
using geometry::cross;
using geometry::norm;
using geometry::scale;
using geometry::sub;

// Cells ranked below this are worth moving nodes for.
constexpr double kComfortable = 0.45;
// Table 1's "good" tetrahedra: Q above 0.2.
constexpr double kTetraGood = 0.2;

Point unit(const Point& v) {
  const double n = norm(v);
  return n > 0 ? scale(v, 1 / n) : v;
}

void sort_unique(std::vector<uint32_t>& values) {
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
}

// Unit steps: along the axes (6), or towards every neighbour of a grid
// point (26, the diagonals too).
std::vector<Point> grid_steps(bool diagonals) {
  std::vector<Point> steps;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k)
        if ((i || j || k) && (diagonals || std::abs(i) + std::abs(j) + std::abs(k) == 1))
          steps.push_back(unit(Point{double(i), double(j), double(k)}));
  return steps;
}
const std::vector<Point> kAxisSteps = grid_steps(false);
const std::vector<Point> kWideSteps = grid_steps(true);

// Unit steps across `normal`: four along two perpendicular directions, and
// with `diagonals` the four between them too, written into `steps`.
std::span<const Point> tangent_steps(const Point& normal, bool diagonals,
                                     std::array<Point, 8>& steps) {
  const Point other = std::abs(normal[0]) < 0.6 ? Point{1, 0, 0} : Point{0, 1, 0};
  const Point u = unit(cross(normal, other));
  const Point v = cross(normal, u);
  size_t count = 0;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      if ((i || j) && (diagonals || !(i && j)))
        steps[count++] = unit(add(scale(u, i), scale(v, j)));
  return {steps.data(), count};
}

// How good the cells around a node are: the worst first, then how far the
// others fall short of comfortable.
struct NodeRank {
  double worst = 1;
  double shortfall = 0;
  bool better_than(const NodeRank& other) const {
    if (worst > other.worst + 1e-12) return true;
    if (worst < other.worst - 1e-12) return false;
    return shortfall < other.shortfall - 1e-12;
  }
};

class LayerBuilder {
 public:
  LayerBuilder(const SurfaceOracle& oracle, MixedMesh mesh, const HexLayerParams& params,
               const RunContext& context)
      : oracle_(oracle), mesh_(std::move(mesh)), params_(params), context_(context) {}

  // Extrudes every boundary square of the core to the surface.
  absl::Status extrude(HexLayerFigures& figures) {
    const std::vector<CellFace> squares = label_boundary_faces(mesh_);
    std::unordered_map<uint32_t, uint32_t> slot;  // core node -> index in boundary_
    for (const CellFace& face : squares) {
      for (int k = 0; k < 4; ++k) {
        if (slot.emplace(face.points[k], uint32_t(boundary_.size())).second)
          boundary_.push_back(face.points[k]);
      }
    }
    // Node normals: the squares' outward normals, averaged.
    std::vector<Point> normal(boundary_.size(), Point{0, 0, 0});
    std::vector<std::array<uint32_t, 4>> square_slots;
    for (const CellFace& face : squares) {
      const auto& p = face.points;
      const Point n = unit(cross(sub(mesh_.points[p[2]], mesh_.points[p[0]]),
                                 sub(mesh_.points[p[3]], mesh_.points[p[1]])));
      std::array<uint32_t, 4> s{};
      for (int k = 0; k < 4; ++k) {
        s[k] = slot.at(p[k]);
        normal[s[k]] = add(normal[s[k]], n);
      }
      square_slots.push_back(s);
    }
    for (auto& n : normal) n = unit(n);
    // Averaging over neighbouring squares turns the grid's steps into the
    // surface's slope.
    for (int round = 0; round < params_.normal_smoothing; ++round) {
      std::vector<Point> next(normal.size(), Point{0, 0, 0});
      for (const auto& s : square_slots) {
        Point mean{0, 0, 0};
        for (uint32_t v : s) mean = add(mean, normal[v]);
        mean = unit(mean);
        for (uint32_t v : s) next[v] = add(next[v], mean);
      }
      for (size_t v = 0; v < next.size(); ++v) normal[v] = unit(next[v]);
    }
    LABELMESH_RETURN_IF_ERROR(context_.check_stop());

    // The outer nodes, where the rays leave the surface.
    outer_.resize(boundary_.size());
    std::vector<double> length(boundary_.size());
    for (size_t v = 0; v < boundary_.size(); ++v) {
      const Point from = mesh_.points[boundary_[v]];  // a copy: points grow below
      const auto hit = oracle_.first_hit(from, normal[v]);
      if (!hit) {
        return absl::FailedPreconditionError(
            "a ray from the core's boundary along its normal misses the surface");
      }
      outer_[v] = uint32_t(mesh_.points.size());
      mesh_.points.push_back(*hit);
      length[v] = norm(sub(*hit, from));
    }
    on_surface_.assign(mesh_.points.size(), 0);
    normal_.assign(mesh_.points.size(), Point{0, 0, 0});
    for (size_t v = 0; v < outer_.size(); ++v) {
      on_surface_[outer_[v]] = 1;
      normal_[outer_[v]] = normal[v];
    }
    const int32_t label = mesh_.labels.empty() ? 0 : mesh_.labels.front();
    for (size_t f = 0; f < squares.size(); ++f) {
      std::array<uint32_t, 8> hex{};
      for (int k = 0; k < 4; ++k) {
        hex[k] = squares[f].points[k];
        hex[k + 4] = outer_[square_slots[f][k]];
      }
      mesh_.add(CellType::kHexahedron, hex, label);
    }
    figures.layer_hexahedra = squares.size();
    index_cells();

    // The core's boundary nodes move towards one common depth below the
    // surface, which irons out the grid's steps, as far as the cells around
    // them allow.
    std::vector<double> sorted = length;
    std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
    const double depth = sorted.empty() ? 0 : sorted[sorted.size() / 2];
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t v = 0; v < boundary_.size(); ++v) {
        const uint32_t node = boundary_[v];
        const Point from = mesh_.points[node];
        const Point target = sub(mesh_.points[outer_[v]], scale(normal[v], depth));
        const NodeRank before = rank(node);
        const double floor = std::min(before.worst, kComfortable);
        bool moved = false;
        for (double share : {1.0, 0.5, 0.25}) {
          mesh_.points[node] = add(from, scale(sub(target, from), share));
          if (rank(node).worst >= floor) {
            moved = true;
            break;
          }
        }
        if (!moved) mesh_.points[node] = from;
      }
      LABELMESH_RETURN_IF_ERROR(context_.check_stop());
    }
    return absl::OkStatus();
  }

  // Pattern search: each node of a poor cell tries a step along each axis
  // (outer nodes then return to the surface) and keeps the best that ranks
  // its cells higher. No move lowers the worst cell around the node.
  absl::Status search() {
    rank_.resize(mesh_.size());
    for (size_t c = 0; c < mesh_.size(); ++c) rank_[c] = layer_cell_rank(mesh_, c);
    const double h = params_.cell_mm;
    for (double step : {0.2 * h, 0.1 * h, 0.05 * h, 0.025 * h, 0.0125 * h}) {
      // A node is tried again only when it or a neighbour moved.
      std::vector<uint32_t> work = nodes_below(kComfortable);
      for (int sweep = 0; sweep < 12 && !work.empty(); ++sweep) {
        LABELMESH_RETURN_IF_ERROR(context_.check_stop());
        std::vector<uint32_t> next;
        for (uint32_t node : work) {
          if (!improve(node, step)) continue;
          for (uint32_t c : cells_of_[node]) add_nodes_of(c, next);
        }
        sort_unique(next);
        work.clear();
        for (uint32_t node : next)
          if (is_poor(node)) work.push_back(node);
      }
    }
    // Cells still below the floor: their nodes and their neighbours' try the
    // diagonals too, a few rounds.
    for (int round = 0; round < 4; ++round) {
      const std::vector<uint32_t> stuck = stuck_neighbourhood();
      if (stuck.empty()) break;
      for (double step : {0.1 * h, 0.05 * h, 0.025 * h, 0.0125 * h, 0.00625 * h}) {
        LABELMESH_RETURN_IF_ERROR(context_.check_stop());
        for (int sweep = 0; sweep < 8; ++sweep) {
          bool moved = false;
          for (uint32_t node : stuck) moved |= improve(node, step, true);
          if (!moved) break;
        }
      }
    }
    return absl::OkStatus();
  }

  // Splits each hexahedron below the floor into six pyramids about an inner
  // point, where all six clear the floors.
  void split(HexLayerFigures& figures) {
    MixedMesh out;
    out.points = mesh_.points;
    for (size_t c = 0; c < mesh_.size(); ++c) {
      if (mesh_.types[c] == CellType::kHexahedron &&
          quality::hexahedron_jacobian_ratio(cell_points<8>(mesh_, c)) < params_.jacobian_floor) {
        if (auto pyramids = split_one(c, out.points)) {
          for (const auto& p : *pyramids) out.add(CellType::kPyramid, p, mesh_.labels[c]);
          ++figures.split_hexahedra;
          continue;
        }
      }
      out.add(mesh_.types[c], mesh_.cells[c], mesh_.labels[c]);
    }
    mesh_ = std::move(out);
  }

  // Every cell against the floors, the volume against the surface's.
  absl::Status verify(double surface_volume_mm3, HexLayerFigures& figures) const {
    size_t below = 0;
    double worst = 1, volume = 0;
    for (size_t c = 0; c < mesh_.size(); ++c) {
      volume += cell_signed_volume(mesh_, c);
      double jr = 1, aspect = 1, tetra_q = 1;
      if (mesh_.types[c] == CellType::kHexahedron) {
        jr = quality::hexahedron_jacobian_ratio(cell_points<8>(mesh_, c));
      } else if (mesh_.types[c] == CellType::kPyramid) {
        const auto p = cell_points<5>(mesh_, c);
        jr = quality::pyramid_jacobian_ratio(p);
        aspect = quality::pyramid_signed_aspect_ratio(p);
      } else if (mesh_.types[c] == CellType::kTetra) {
        tetra_q = quality::tetra_quality(cell_points<4>(mesh_, c));
      }
      worst = std::min(worst, jr);
      if (!(jr >= params_.jacobian_floor) || !(aspect >= params_.aspect_floor) ||
          !(tetra_q > kTetraGood))
        ++below;
    }
    for (uint32_t o : outer_) {
      figures.boundary_distance_max_mm =
          std::max(figures.boundary_distance_max_mm, std::abs(oracle_.depth(mesh_.points[o])));
    }
    figures.volume_change = surface_volume_mm3 > 0 ? volume / surface_volume_mm3 - 1 : 0;
    if (below > 0) {
      return absl::FailedPreconditionError(
          cat("the hexahedral layer leaves ", below, " cells below Jacobian ratio ",
              params_.jacobian_floor, ", pyramid aspect ratio ", params_.aspect_floor,
              " or tetrahedron Q ", kTetraGood, " (worst Jacobian ratio ", format_fixed(worst, 3),
              ")"));
    }
    if (!(std::abs(figures.volume_change) <= params_.volume_tolerance)) {
      return absl::FailedPreconditionError(
          cat("the hexahedral layer's volume is ",
              format_fixed(100 * std::abs(figures.volume_change), 2), " % ",
              figures.volume_change < 0 ? "below" : "above", " the surface's (at most ",
              100 * params_.volume_tolerance, " % either way)"));
    }
    return absl::OkStatus();
  }

  MixedMesh take() { return std::move(mesh_); }

 private:
  void index_cells() {
    cells_of_.assign(mesh_.points.size(), {});
    for (size_t c = 0; c < mesh_.size(); ++c)
      for (int k = 0; k < node_count(mesh_.types[c]); ++k)
        cells_of_[mesh_.cells[c][k]].push_back(uint32_t(c));
  }

  // The rank of the cells around `node`; stops early, with a rank no better
  // than `bar`, as soon as a cell falls below bar's worst.
  NodeRank rank(uint32_t node, const NodeRank* bar = nullptr) const {
    NodeRank r;
    for (uint32_t c : cells_of_[node]) {
      const double q = layer_cell_rank(mesh_, c);
      r.worst = std::min(r.worst, q);
      r.shortfall += std::max(0.0, kComfortable - q);
      if (bar && r.worst < bar->worst - 1e-12) return r;
    }
    return r;
  }

  void add_nodes_of(uint32_t cell, std::vector<uint32_t>& nodes) const {
    for (int k = 0; k < node_count(mesh_.types[cell]); ++k) nodes.push_back(mesh_.cells[cell][k]);
  }

  // The nodes of the cells ranked below `bar`, in order, each once.
  std::vector<uint32_t> nodes_below(double bar) const {
    std::vector<uint32_t> nodes;
    for (size_t c = 0; c < mesh_.size(); ++c)
      if (rank_[c] < bar) add_nodes_of(uint32_t(c), nodes);
    sort_unique(nodes);
    return nodes;
  }

  // The nodes of cells ranked below the Jacobian floor and of every cell
  // that shares a node with one, in order.
  std::vector<uint32_t> stuck_neighbourhood() const {
    std::vector<uint32_t> nodes;
    for (uint32_t node : nodes_below(params_.jacobian_floor))
      for (uint32_t c : cells_of_[node]) add_nodes_of(c, nodes);
    sort_unique(nodes);
    return nodes;
  }

  bool is_poor(uint32_t node) const {
    for (uint32_t c : cells_of_[node])
      if (rank_[c] < kComfortable) return true;
    return false;
  }

  // Tries steps of `step` from the node: along the axes, or with `wide`
  // also along the diagonals (26 directions; 8 across an outer node's
  // normal). Keeps the best that ranks the cells around higher.
  bool improve(uint32_t node, double step, bool wide = false) {
    const Point from = mesh_.points[node];
    NodeRank best = rank(node);
    Point best_point = from;
    // Outer nodes step along the surface, then return to it.
    std::array<Point, 8> across{};
    const std::span<const Point> directions =
        on_surface_[node] ? tangent_steps(normal_[node], wide, across)
                          : std::span<const Point>(wide ? kWideSteps : kAxisSteps);
    for (const Point& direction : directions) {
      Point candidate = add(from, scale(direction, step));
      if (on_surface_[node]) candidate = oracle_.closest(candidate);
      if (norm(sub(candidate, from)) < 1e-9 * params_.cell_mm) continue;
      mesh_.points[node] = candidate;
      const NodeRank r = rank(node, &best);
      if (r.better_than(best)) {
        best = r;
        best_point = candidate;
      }
    }
    mesh_.points[node] = best_point;
    if (best_point == from) return false;
    for (uint32_t c : cells_of_[node]) rank_[c] = layer_cell_rank(mesh_, c);
    return true;
  }

  // Six pyramids for hexahedron c about an inner point, or none when they
  // miss a floor. Adds the apex to `points`.
  std::optional<std::array<std::array<uint32_t, 8>, 6>> split_one(size_t c,
                                                                  std::vector<Point>& points) {
    const auto apex = split_apex(cell_points<8>(mesh_, c), params_);
    if (!apex) return std::nullopt;
    points.push_back(*apex);
    return pyramids_of(mesh_.cells[c], uint32_t(points.size() - 1));
  }

  const SurfaceOracle& oracle_;
  MixedMesh mesh_;
  const HexLayerParams& params_;
  const RunContext& context_;
  std::vector<uint32_t> boundary_;  // the core's boundary nodes
  std::vector<uint32_t> outer_;     // their outer nodes, slot for slot
  std::vector<uint8_t> on_surface_;
  std::vector<Point> normal_;  // of the outer nodes: their ray's direction
  std::vector<std::vector<uint32_t>> cells_of_;
  std::vector<double> rank_;  // layer_cell_rank of each cell, while searching
};

}  // namespace

std::array<std::array<uint32_t, 8>, 6> pyramids_of(const std::array<uint32_t, 8>& hex,
                                                   uint32_t apex) {
  std::array<std::array<uint32_t, 8>, 6> pyramids{};
  for (int f = 0; f < 6; ++f) {
    const auto base = hexahedron_face_inward(f);
    for (int k = 0; k < 4; ++k) pyramids[f][k] = hex[base[k]];
    pyramids[f][4] = apex;
  }
  return pyramids;
}

// min(JR, 2 × scaled Jacobian) from one pass over the corners (the
// layer's search calls it most).
double hexahedron_rank(const quality::Hex& p) {
  const quality::HexCorners corners = quality::hexahedron_corners(p);
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest, scaled = 1;
  for (int k = 0; k < 8; ++k) {
    const double j = corners.jacobian[k];
    lowest = std::min(lowest, j);
    highest = std::max(highest, j);
    const double lengths = corners.edge_lengths[k];
    scaled = std::min(scaled, lengths > 0 ? j / lengths : 0.0);
  }
  // An inverted corner ranks below any valid cell, by how far the worst
  // corner is folded: the ratio alone is flat (-1) once every corner is.
  if (!(lowest > 0)) return 2 * scaled - 2;
  return std::min(lowest / highest, 2 * scaled);
}

std::optional<Point> split_apex(const std::array<Point, 8>& hex, const HexLayerParams& params) {
  std::array<Point, 9> points;
  std::copy(hex.begin(), hex.end(), points.begin());
  Point apex{0, 0, 0};
  for (const Point& p : hex) apex = add(apex, p);
  apex = scale(apex, 1.0 / 8);
  const auto pyramids = pyramids_of({0, 1, 2, 3, 4, 5, 6, 7}, 8);
  // The worst pyramid's figures, each over its floor: 1 or more clears both.
  auto score = [&](const Point& at) {
    points[8] = at;
    double worst = std::numeric_limits<double>::infinity();
    for (const auto& p : pyramids) {
      quality::Pyramid corners5;
      for (int k = 0; k < 5; ++k) corners5[k] = points[p[k]];
      worst = std::min({worst, quality::pyramid_jacobian_ratio(corners5) / params.jacobian_floor,
                        quality::pyramid_signed_aspect_ratio(corners5) / params.aspect_floor});
    }
    return worst;
  };
  double best = score(apex);
  for (double step = 0.1 * params.cell_mm; step > 0.005 * params.cell_mm; step /= 2) {
    for (bool moved = true; moved;) {
      moved = false;
      for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {-1.0, 1.0}) {
          Point candidate = apex;
          candidate[axis] += sign * step;
          if (const double s = score(candidate); s > best + 1e-12) {
            best = s;
            apex = candidate;
            moved = true;
          }
        }
      }
    }
  }
  if (best >= 1) return apex;
  return std::nullopt;
}

double layer_cell_rank(const MixedMesh& mesh, size_t cell) {
  switch (mesh.types[cell]) {
    case CellType::kHexahedron:
      return hexahedron_rank(cell_points<8>(mesh, cell));
    case CellType::kPyramid: {
      const auto p = cell_points<5>(mesh, cell);
      return std::min(quality::pyramid_jacobian_ratio(p), quality::pyramid_signed_aspect_ratio(p));
    }
    case CellType::kWedge:
      return quality::wedge_jacobian_ratio(cell_points<6>(mesh, cell));
    case CellType::kTetra:
      return quality::tetra_quality(cell_points<4>(mesh, cell));
  }
  return -1;
}

absl::StatusOr<MixedMesh> add_hex_layer(const SurfaceOracle& oracle, double surface_volume_mm3,
                                        MixedMesh core, const HexLayerParams& params,
                                        const RunContext& context, HexLayerFigures& figures) {
  if (core.size() == 0) return absl::FailedPreconditionError("the label has no hexahedral core");
  LayerBuilder builder(oracle, std::move(core), params, context);
  LABELMESH_RETURN_IF_ERROR(builder.extrude(figures));
  LABELMESH_RETURN_IF_ERROR(builder.search());
  if (params.split) builder.split(figures);
  LABELMESH_RETURN_IF_ERROR(builder.verify(surface_volume_mm3, figures));
  return builder.take();
}

}  // namespace labelmesh::mixed_mesh
