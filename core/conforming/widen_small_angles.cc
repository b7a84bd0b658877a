// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/widen_small_angles.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;

// An edge from one point to another, and its length.
struct Edge {
  Vec3 along;
  double length;
};

Edge edge(const Vec3& from, const Vec3& to) {
  const Vec3 along = geometry::sub(to, from);
  return {along, geometry::norm(along)};
}

Edge reversed(const Edge& e) { return {geometry::scale(e.along, -1), e.length}; }

// The cosine of the angle between two edges leaving one corner (1 where
// one has no length).
double corner_cosine(const Edge& u, const Edge& w) {
  const double lengths = u.length * w.length;
  return lengths > 0 ? geometry::dot(u.along, w.along) / lengths : 1.0;
}

// The largest cosine among the angles of triangle (p, q, r), its smallest
// angle's, from its edges p -> q, q -> r and p -> r: quads share edges
// between their two splits, so each length is taken once.
double smallest_angle_cosine(const Edge& pq, const Edge& qr, const Edge& pr) {
  return std::max({corner_cosine(pq, pr), corner_cosine(qr, reversed(pq)),
                   corner_cosine(reversed(pr), reversed(qr))});
}

// The quads around each point, as offsets into one list.
struct QuadsAround {
  std::vector<uint32_t> start;
  std::vector<uint32_t> quads;
};

QuadsAround quads_around(const std::vector<std::array<uint32_t, 4>>& quads, size_t points) {
  QuadsAround around;
  around.start.assign(points + 1, 0);
  for (const auto& quad : quads)
    for (const uint32_t p : quad) ++around.start[p + 1];
  for (size_t p = 0; p < points; ++p) around.start[p + 1] += around.start[p];
  around.quads.resize(around.start[points]);
  std::vector<uint32_t> filled(around.start.begin(), around.start.end() - 1);
  for (uint32_t q = 0; q < quads.size(); ++q)
    for (const uint32_t p : quads[q]) around.quads[filled[p]++] = q;
  return around;
}

// Splits the quad of triangles t and t + 1 (sharing an edge) along the
// diagonal that gives the larger smallest angle, keeping their winding.
void resplit_quad(InterfaceSurface& surface, uint32_t t) {
  auto& first = surface.triangles[t];
  auto& second = surface.triangles[t + 1];
  // first runs u -> v along the shared edge, x its third corner; second
  // runs v -> u, y its third: the quad is u, y, v, x in order.
  const auto in_second = [&](uint32_t corner) {
    return std::find(second.begin(), second.end(), corner) != second.end();
  };
  int k = 0;
  while (k < 3 && !(in_second(first[k]) && in_second(first[(k + 1) % 3]))) ++k;
  if (k == 3) return;
  const uint32_t u = first[k], v = first[(k + 1) % 3], x = first[(k + 2) % 3];
  uint32_t y = second[0];
  for (const uint32_t corner : second)
    if (corner != u && corner != v) y = corner;
  // Split along u-v, the quad's 0-2 diagonal, as now; else along y-x.
  if (best_quad_split({u, y, v, x}, surface.points).along_02) return;
  first = {u, y, x};
  second = {y, v, x};
}

}  // namespace

QuadSplit best_quad_split(const std::array<uint32_t, 4>& quad, const std::vector<Vec3>& points) {
  const Vec3 &a = points[quad[0]], &b = points[quad[1]], &c = points[quad[2]], &d = points[quad[3]];
  const Edge ab = edge(a, b), bc = edge(b, c), cd = edge(c, d), ad = edge(a, d), ac = edge(a, c),
             bd = edge(b, d);
  const double split_02 =
      std::max(smallest_angle_cosine(ab, bc, ac), smallest_angle_cosine(ac, cd, ad));
  const double split_13 =
      std::max(smallest_angle_cosine(ab, bd, ad), smallest_angle_cosine(bc, cd, bd));
  return split_02 <= split_13 ? QuadSplit{split_02, true} : QuadSplit{split_13, false};
}

WidenedAngles widen_small_angles(const std::vector<std::array<uint32_t, 4>>& quads,
                                 const std::vector<std::array<int32_t, 2>>& quad_sides,
                                 const std::vector<Slide>& slides, const std::vector<Vec3>& centre,
                                 const PointBoxes& boxes, const Vec3& across,
                                 const AngleLimits& limits, std::vector<Vec3>& points) {
  WidenedAngles result;
  const auto cosine_of = [](double deg) { return std::cos(deg * M_PI / 180); };
  const double limit = cosine_of(limits.below_deg);
  const double far_limit = cosine_of(std::min(limits.far_below_deg, limits.below_deg));
  const QuadsAround around = quads_around(quads, points.size());
  // The worst (largest) smallest-angle cosine among the quads around p.
  const auto worst_around = [&](uint32_t p) {
    double worst = -1;
    for (uint32_t i = around.start[p]; i < around.start[p + 1]; ++i)
      worst = std::max(worst, best_quad_split(quads[around.quads[i]], points).cosine);
    return worst;
  };
  // Towards the middle of p's neighbours along the quads' edges, within the
  // surface's tangent plane at p (its quads oriented alike).
  const auto tangential_move = [&](uint32_t p) {
    Vec3 normal{0, 0, 0}, middle{0, 0, 0};
    int neighbours = 0;
    for (uint32_t i = around.start[p]; i < around.start[p + 1]; ++i) {
      const uint32_t q = around.quads[i];
      const auto& c = quads[q];
      Vec3 n = geometry::cross(geometry::sub(points[c[2]], points[c[0]]),
                               geometry::sub(points[c[3]], points[c[1]]));
      if (quad_sides[q][0] > quad_sides[q][1]) n = geometry::scale(n, -1);
      normal = geometry::add(normal, n);
      const auto k = std::find(c.begin(), c.end(), p) - c.begin();
      middle = geometry::add(middle, geometry::add(points[c[(k + 1) % 4]], points[c[(k + 3) % 4]]));
      neighbours += 2;
    }
    if (neighbours == 0) return Vec3{0, 0, 0};
    Vec3 move = geometry::sub(geometry::scale(middle, 1.0 / neighbours), points[p]);
    // Where the quads' normals cancel (two sheets meeting at the point)
    // there is no tangent plane: the move stays in the box all the same.
    const double length = geometry::norm(normal);
    if (length == 0) return move;
    const Vec3 unit = geometry::scale(normal, 1 / length);
    return geometry::sub(move, geometry::scale(unit, geometry::dot(move, unit)));
  };

  // Moves p where the smallest angle of its quads grows most: along the
  // surface first; across it (along a voxel axis, the shape changing inside
  // the box) where that is not enough. Whether it moved.
  const auto widen_at = [&](uint32_t p) {
    const double before = worst_around(p);
    if (before <= limit) return false;
    const Vec3 from = points[p];
    std::vector<Vec3> along;
    if (slides[p].kind == Slide::Kind::kSurface) {
      const Vec3 move = tangential_move(p);
      along = {move, geometry::scale(move, 0.5), geometry::scale(move, 0.25)};
    } else {
      const Vec3 curve = geometry::sub(points[slides[p].curve[1]], points[slides[p].curve[0]]);
      for (const double fraction : {0.25, 0.125, -0.125, -0.25})
        along.push_back(geometry::scale(curve, fraction));
    }
    const auto across_moves = [&](double fraction) {
      std::vector<Vec3> moves;
      for (int k = 0; k < 3; ++k)
        for (const double sign : {-1.0, 1.0}) {
          Vec3 move{0, 0, 0};
          move[k] = sign * fraction * across[k];
          moves.push_back(move);
        }
      return moves;
    };
    double best = before;
    Vec3 best_place = from;
    const auto try_moves = [&](const std::vector<Vec3>& moves) {
      for (const Vec3& move : moves) {
        points[p] = boxes.hold(p, centre[p], geometry::add(from, move));
        const double worst = worst_around(p);
        if (worst < best) {
          best = worst;
          best_place = points[p];
        }
      }
    };
    try_moves(along);
    if (best > far_limit) {
      try_moves(across_moves(1));
    } else if (best > limit) {
      try_moves(across_moves(limits.short_fraction));
    }
    points[p] = best_place;
    return points[p] != from;
  };

  // The slidable points of the quads below the limit among `quads_of`.
  const auto points_of_thin_quads = [&](const auto& quads_of) {
    std::vector<uint32_t> found;
    quads_of([&](uint32_t q) {
      if (best_quad_split(quads[q], points).cosine <= limit) return;
      for (const uint32_t p : quads[q])
        if (slides[p].kind != Slide::Kind::kFixed) found.push_back(p);
    });
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    return found;
  };
  std::vector<uint32_t> candidates = points_of_thin_quads([&](const auto& visit) {
    for (uint32_t q = 0; q < quads.size(); ++q) visit(q);
  });
  // Where each moved point started: one moved in a pass may come back in a
  // later one, and counts only if it ends elsewhere.
  std::unordered_map<uint32_t, Vec3> started;
  for (int pass = 0; pass < kWideningPasses && !candidates.empty(); ++pass) {
    std::vector<uint32_t> moved_now;
    for (const uint32_t p : candidates) {
      const Vec3 from = points[p];
      if (!widen_at(p)) continue;
      moved_now.push_back(p);
      started.emplace(p, from);
    }
    candidates = points_of_thin_quads([&](const auto& visit) {
      for (const uint32_t p : moved_now)
        for (uint32_t i = around.start[p]; i < around.start[p + 1]; ++i) visit(around.quads[i]);
    });
  }
  result.points_moved = static_cast<size_t>(std::count_if(
      started.begin(), started.end(), [&](const auto& s) { return points[s.first] != s.second; }));
  return result;
}

std::vector<uint32_t> take_back_crossing_slides(InterfaceSurface& surface,
                                                const surface::TrianglePairs& crossing) {
  std::vector<uint32_t> resplit;
  if (surface.widened.empty() || crossing.empty()) return resplit;
  std::vector<bool> in_crossing(surface.points.size(), false);
  for (const auto& [s, t] : crossing)
    for (const uint32_t triangle : {s, t})
      for (const uint32_t p : surface.triangles[triangle]) in_crossing[p] = true;
  auto& widened = surface.widened;
  // Points moved now; those back where smoothing left them leave the list.
  std::vector<bool> taken_back(surface.points.size(), false);
  std::vector<bool> taken_back_wholly(surface.points.size(), false);
  for (auto& slid : widened) {
    if (!in_crossing[slid.point]) continue;
    auto& place = surface.points[slid.point];
    if (slid.halvings == kHalvings) {
      place = slid.before;
      taken_back_wholly[slid.point] = true;
    } else {
      place = geometry::scale(geometry::add(place, slid.before), 0.5);
      ++slid.halvings;
    }
    taken_back[slid.point] = true;
  }
  widened.erase(std::remove_if(widened.begin(), widened.end(),
                               [&](const auto& slid) { return taken_back_wholly[slid.point]; }),
                widened.end());
  for (uint32_t t = 0; t + 1 < surface.triangles.size(); t += 2) {
    const auto& a = surface.triangles[t];
    const auto& b = surface.triangles[t + 1];
    const auto touched = [&](const std::array<uint32_t, 3>& triangle) {
      return taken_back[triangle[0]] || taken_back[triangle[1]] || taken_back[triangle[2]];
    };
    if (!touched(a) && !touched(b)) continue;
    resplit_quad(surface, t);
    resplit.push_back(t);
    resplit.push_back(t + 1);
  }
  return resplit;
}

surface::TrianglePairs crossings_after_taking_back_slides(InterfaceSurface& surface) {
  auto pairs = surface::crossing_triangles(surface.points, surface.triangles);
  // Each round halves or takes back at least one slide, and a slide is
  // halved at most kHalvings times: the rounds end.
  for (;;) {
    const auto among = take_back_crossing_slides(surface, pairs);
    if (among.empty()) break;
    // Only pairs with a triangle of a quad taken back can change.
    std::vector<bool> near(surface.triangles.size(), false);
    for (const uint32_t t : among) near[t] = true;
    pairs.erase(
        std::remove_if(pairs.begin(), pairs.end(),
                       [&](const auto& pair) { return near[pair.first] || near[pair.second]; }),
        pairs.end());
    const auto found = surface::crossing_triangles_near(surface.points, surface.triangles, among);
    pairs.insert(pairs.end(), found.begin(), found.end());
    std::sort(pairs.begin(), pairs.end());
  }
  return pairs;
}

}  // namespace labelmesh::conforming
