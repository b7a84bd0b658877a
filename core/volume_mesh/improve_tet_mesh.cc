// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/improve_tet_mesh.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_set>
#include <vector>

#include "core/quality/element_quality.h"
#include "core/util/vec3.h"

namespace labelmesh::volume_mesh {
namespace {

using geometry::Vec3;
using Tet = std::array<uint32_t, 4>;
constexpr double kNone = std::numeric_limits<double>::infinity();

// The mesh while it is being improved: tetrahedra are removed by marking
// them dead, and each point knows the live tetrahedra around it.
class WorkMesh {
 public:
  WorkMesh(TetMesh& mesh, const ImproveParams& params)
      : max_volume(params.max_volume_mm3),
        max_peel_depth(params.max_peel_depth_mm),
        dihedral_scale_(params.target_dihedral_deg > 0
                            ? params.target_quality / params.target_dihedral_deg
                            : 0),
        mesh_(mesh),
        star_(mesh.points.size()) {
    tets_.reserve(mesh.tetrahedra.size() + mesh.tetrahedra.size() / 8);
    for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) add(mesh.tetrahedra[t], mesh.labels[t]);
    mark_boundary_points();
  }

  const double max_volume;      // 0: no bound
  const double max_peel_depth;  // 0: no peeling

  size_t size() const { return tets_.size(); }
  bool alive(uint32_t t) const { return alive_[t]; }
  const Tet& tet(uint32_t t) const { return tets_[t]; }
  int32_t label(uint32_t t) const { return labels_[t]; }
  double quality(uint32_t t) const { return quality_[t]; }
  bool fixed(uint32_t v) const { return fixed_[v]; }
  // Points of slivers peeled off the surface so far.
  bool peeled(uint32_t v) const { return peeled_.contains(v); }
  void mark_peeled(uint32_t v) { peeled_.insert(v); }
  const std::vector<uint32_t>& star(uint32_t v) const { return star_[v]; }
  Vec3& point(uint32_t v) { return mesh_.points[v]; }

  // Q, or with a dihedral target the lower of Q and the smallest dihedral
  // angle scaled to Q's target: what every operation must raise.
  double quality_of(const Tet& t) const {
    const auto p = corners(t);
    const double q = quality::tetra_quality(p);
    if (dihedral_scale_ == 0) return q;
    return std::min(q, dihedral_scale_ * quality::tetra_dihedral_range_deg(p).first);
  }
  // Q alone, for the figures and the peeling rule.
  double plain_q(uint32_t t) const { return quality::tetra_quality(corners(tets_[t])); }
  double volume_of(const Tet& t) const { return quality::tetra_signed_volume(corners(t)); }

  uint32_t add(const Tet& t, int32_t label) {
    const auto id = static_cast<uint32_t>(tets_.size());
    tets_.push_back(t);
    labels_.push_back(label);
    alive_.push_back(true);
    quality_.push_back(quality_of(t));
    for (uint32_t v : t) star_[v].push_back(id);
    return id;
  }

  void remove(uint32_t t) {
    alive_[t] = false;
    for (uint32_t v : tets_[t]) std::erase(star_[v], t);
  }

  // Undoes remove(t): t keeps its id, so callers' handles stay valid.
  void revive(uint32_t t) {
    alive_[t] = true;
    for (uint32_t v : tets_[t]) star_[v].push_back(t);
  }

  void requalify(uint32_t t) { quality_[t] = quality_of(tets_[t]); }

  // A new interior point (free to move) at `p`.
  uint32_t add_point(const Vec3& p) {
    mesh_.points.push_back(p);
    star_.emplace_back();
    fixed_.push_back(false);
    return static_cast<uint32_t>(mesh_.points.size() - 1);
  }
  // Takes back the point add_point() gave last; no tetrahedron may use it.
  void drop_last_point() {
    mesh_.points.pop_back();
    star_.pop_back();
    fixed_.pop_back();
  }

  // The live tetrahedron other than `t` that has face a, b, c, if any.
  std::optional<uint32_t> across(uint32_t t, uint32_t a, uint32_t b, uint32_t c) const {
    for (uint32_t other : star_[a]) {
      if (other != t && has(other, b) && has(other, c)) return other;
    }
    return std::nullopt;
  }

  bool has(uint32_t t, uint32_t v) const {
    const Tet& k = tets_[t];
    return k[0] == v || k[1] == v || k[2] == v || k[3] == v;
  }

  void write_back() {
    TetMesh& m = mesh_;
    m.tetrahedra.clear();
    m.labels.clear();
    for (size_t t = 0; t < tets_.size(); ++t) {
      if (!alive_[t]) continue;
      m.tetrahedra.push_back(tets_[t]);
      m.labels.push_back(labels_[t]);
    }
    drop_unused_points();
  }

 private:
  // An insertion whose cavity held a point's whole star leaves that point in
  // no tetrahedron: it would be a node of no element in the written mesh.
  void drop_unused_points() {
    TetMesh& m = mesh_;
    std::vector<uint8_t> used(m.points.size(), 0);
    for (const Tet& t : m.tetrahedra) {
      for (uint32_t v : t) used[v] = 1;
    }
    if (std::all_of(used.begin(), used.end(), [](uint8_t u) { return u != 0; })) return;
    std::vector<uint32_t> renumbered(m.points.size());
    uint32_t kept = 0;
    for (uint32_t v = 0; v < m.points.size(); ++v) {
      renumbered[v] = kept;
      if (used[v]) m.points[kept++] = m.points[v];
    }
    m.points.resize(kept);
    for (Tet& t : m.tetrahedra) {
      for (uint32_t& v : t) v = renumbered[v];
    }
  }

  // The points of every label's boundary faces (its surface and its
  // interfaces with other labels) stay where they are.
  void mark_boundary_points() {
    fixed_.assign(mesh_.points.size(), false);
    for (const BoundaryFace& face : label_boundary_faces(mesh_)) {
      for (uint32_t v : face.points) fixed_[v] = true;
    }
  }

  quality::Tet corners(const Tet& t) const {
    return {mesh_.points[t[0]], mesh_.points[t[1]], mesh_.points[t[2]], mesh_.points[t[3]]};
  }

  const double dihedral_scale_;  // target Q per degree; 0: Q alone
  TetMesh& mesh_;
  std::vector<Tet> tets_;
  std::vector<int32_t> labels_;
  std::vector<char> alive_;
  std::vector<double> quality_;
  std::vector<std::vector<uint32_t>> star_;
  std::vector<char> fixed_;
  std::unordered_set<uint32_t> peeled_;
};

double lowest_quality(const WorkMesh& w, const std::vector<uint32_t>& tets) {
  double lowest = kNone;
  for (uint32_t t : tets) lowest = std::min(lowest, w.quality(t));
  return lowest;
}

double total_volume(const WorkMesh& w, const std::vector<uint32_t>& tets) {
  double sum = 0;
  for (uint32_t t : tets) sum += w.volume_of(w.tet(t));
  return sum;
}

// True when no tetrahedron of `new_tets` is inverted and together they have
// `old_volume`. The same volume means the same region: a flip whose new edge
// misses the old shared face, or a point outside its cavity's kernel, would
// cover more than the old tetrahedra did.
bool fills_same_region(const WorkMesh& w, const std::vector<Tet>& new_tets, double old_volume) {
  double new_volume = 0;
  for (const Tet& t : new_tets) {
    const double v = w.volume_of(t);
    if (!(v > 0)) return false;
    new_volume += v;
  }
  return std::abs(new_volume - old_volume) <= 1e-9 * old_volume;
}

// Replaces `old_tets` by `new_tets` when the new ones fill the same region,
// none exceeds the volume bound, and their worst quality beats the old worst.
bool replace_if_better(WorkMesh& w, const std::vector<uint32_t>& old_tets,
                       const std::vector<Tet>& new_tets) {
  if (!fills_same_region(w, new_tets, total_volume(w, old_tets))) return false;
  double old_largest = 0;
  for (uint32_t t : old_tets) old_largest = std::max(old_largest, w.volume_of(w.tet(t)));
  double new_lowest = kNone;
  for (const Tet& t : new_tets) {
    const double v = w.volume_of(t);
    if (w.max_volume > 0 && v > w.max_volume && v > old_largest) return false;
    new_lowest = std::min(new_lowest, w.quality_of(t));
  }
  if (!(new_lowest > lowest_quality(w, old_tets))) return false;
  const int32_t label = w.label(old_tets.front());
  for (uint32_t t : old_tets) w.remove(t);
  for (const Tet& t : new_tets) w.add(t, label);
  return true;
}

// The face of `t` opposite its local vertex `across`, wound so that its
// right-hand normal points into `t` (towards that vertex): a new point on
// that side makes a positive tetrahedron with it.
std::array<uint32_t, 3> inward_face(const Tet& t, uint8_t across) {
  const auto& f = outward_face(across);
  return {t[f[0]], t[f[2]], t[f[1]]};
}

// 2-3 flip: tetrahedra a,b,c,d and its neighbour across a,b,c (apex e) become
// three around the new edge d-e.
bool flip_2_3(WorkMesh& w, uint32_t t, int face, ImproveFigures& figures) {
  const Tet& k = w.tet(t);
  // Local vertex `face` is d; a,b,c are the others, ordered so that a,b,c,d
  // is positive (the VTK ordering of the face opposite each vertex).
  const auto [a, b, c] = inward_face(k, uint8_t(face));
  const uint32_t d = k[face];
  const auto neighbour = w.across(t, a, b, c);
  if (!neighbour || w.label(*neighbour) != w.label(t)) return false;
  uint32_t e = 0;
  for (uint32_t v : w.tet(*neighbour)) {
    if (v != a && v != b && v != c) e = v;
  }
  // a,b,c,d positive puts d above a,b,c and e below it; then x,y,e,d is
  // positive for each edge x,y of a,b,c.
  const std::vector<Tet> flipped = {{a, b, e, d}, {b, c, e, d}, {c, a, e, d}};
  if (!replace_if_better(w, {t, *neighbour}, flipped)) return false;
  ++figures.flips_2_3;
  return true;
}

// 3-2 flip: the three tetrahedra around interior edge a-b become two that
// share the face c,d,e their other points make.
bool flip_3_2(WorkMesh& w, uint32_t a, uint32_t b, ImproveFigures& figures) {
  std::vector<uint32_t> ring;
  for (uint32_t t : w.star(a)) {
    if (w.has(t, b)) ring.push_back(t);
  }
  if (ring.size() != 3) return false;
  // The other points of each ring tetrahedron; around an interior edge with
  // three tetrahedra they form a cycle of three points, each seen twice.
  std::vector<uint32_t> others;
  for (uint32_t t : ring) {
    if (w.label(t) != w.label(ring[0])) return false;
    for (uint32_t v : w.tet(t)) {
      if (v != a && v != b) others.push_back(v);
    }
  }
  std::vector<uint32_t> distinct = others;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  if (distinct.size() != 3) return false;
  const uint32_t c = distinct[0], d = distinct[1], e = distinct[2];
  Tet upper = {c, d, e, a}, lower = {d, c, e, b};
  if (w.volume_of(upper) < 0) {
    upper = {d, c, e, a};
    lower = {c, d, e, b};
  }
  if (!replace_if_better(w, ring, {upper, lower})) return false;
  ++figures.flips_3_2;
  return true;
}

double star_lowest(const WorkMesh& w, uint32_t v) {
  double lowest = kNone;
  for (uint32_t t : w.star(v)) lowest = std::min(lowest, w.quality_of(w.tet(t)));
  return lowest;
}

// Moves interior point v to where the worst tetrahedron around it is best,
// trying the centroid of its neighbours and steps up the gradient of the
// worst one's quality; keeps a move only if the star's minimum rises.
bool smooth_vertex(WorkMesh& w, uint32_t v, ImproveFigures& figures) {
  if (w.fixed(v) || w.star(v).empty()) return false;
  Vec3& p = w.point(v);
  const Vec3 start = p;
  double best = star_lowest(w, v);
  Vec3 best_point = p;

  Vec3 centroid = {0, 0, 0};
  double edge_sum = 0;
  size_t n = 0;
  for (uint32_t t : w.star(v)) {
    for (uint32_t u : w.tet(t)) {
      if (u == v) continue;
      const Vec3& q = w.point(u);
      centroid = geometry::add(centroid, q);
      edge_sum += geometry::norm(geometry::sub(q, start));
      ++n;
    }
  }
  centroid = geometry::scale(centroid, 1.0 / double(n));
  const double length = edge_sum / double(n);

  auto try_point = [&](const Vec3& candidate) {
    p = candidate;
    const double lowest = star_lowest(w, v);
    if (lowest > best) {
      best = lowest;
      best_point = candidate;
    }
  };
  for (double s : {1.0, 0.5, 0.25}) {
    try_point(geometry::add(start, geometry::scale(geometry::sub(centroid, start), s)));
  }
  // Gradient ascent on the worst tetrahedra, from the best point so far.
  // First along the direction that raises every one within 0.01 of the worst
  // (the sum of their unit gradients), so that two tied worst ones do not
  // undo each other's step; if that fails, along the worst one's own.
  auto unit_gradient = [&](uint32_t t) {
    const double h = 1e-4 * length;
    Vec3 gradient;
    for (int k = 0; k < 3; ++k) {
      p = best_point;
      p[k] += h;
      const double up = w.quality_of(w.tet(t));
      p[k] -= 2 * h;
      const double down = w.quality_of(w.tet(t));
      gradient[k] = (up - down) / (2 * h);
    }
    p = best_point;
    const double size = geometry::norm(gradient);
    return size > 0 ? geometry::scale(gradient, 1 / size) : Vec3{0, 0, 0};
  };
  auto climb = [&](const Vec3& direction) {
    const double size = geometry::norm(direction);
    if (!(size > 0)) return false;
    const double before = best;
    const Vec3 from = best_point;
    for (double s : {0.2, 0.1, 0.05, 0.02, 0.005}) {
      try_point(geometry::add(from, geometry::scale(direction, s * length / size)));
    }
    return best > before + 1e-6;
  };
  for (int step = 0; step < 12; ++step) {
    p = best_point;
    uint32_t worst = w.star(v).front();
    double worst_q = kNone;
    Vec3 together = {0, 0, 0};
    for (uint32_t t : w.star(v)) {
      const double q = w.quality_of(w.tet(t));
      if (q < worst_q) {
        worst_q = q;
        worst = t;
      }
      if (q < best + 0.01) together = geometry::add(together, unit_gradient(t));
    }
    if (!climb(together) && !climb(unit_gradient(worst))) break;
  }
  p = best_point;
  if (best_point == start) return false;
  for (uint32_t t : w.star(v)) w.requalify(t);
  ++figures.vertices_moved;
  return true;
}

// Vertex insertion: the tetrahedra of t's label around t's points make a
// cavity; a new point inside it is joined to every face of the cavity's
// boundary and moved to where the worst new tetrahedron is best. This is what
// removes a sliver whose four points all lie on the boundary (two of its faces
// on the surface), which no flip or interior move can reach.
bool insert_in_cavity(WorkMesh& w, uint32_t t, std::vector<uint32_t> cavity,
                      ImproveFigures& figures) {
  const int32_t label = w.label(t);
  const Tet k = w.tet(t);
  std::sort(cavity.begin(), cavity.end());
  cavity.erase(std::unique(cavity.begin(), cavity.end()), cavity.end());
  auto in_cavity = [&](uint32_t x) { return std::binary_search(cavity.begin(), cavity.end(), x); };
  // The cavity's boundary, each face wound so its normal points inwards; t's
  // faces on its label's boundary give the direction into the label.
  std::vector<std::array<uint32_t, 3>> faces;
  Vec3 inward = {0, 0, 0};
  for (uint32_t c : cavity) {
    const Tet& ck = w.tet(c);
    for (uint8_t across = 0; across < 4; ++across) {
      const auto face = inward_face(ck, across);
      const auto other = w.across(c, face[0], face[1], face[2]);
      if (other && in_cavity(*other)) continue;
      faces.push_back(face);
      // Outer faces and interfaces with other labels alike bound t's label.
      if ((!other || w.label(*other) != label) && c == t) {
        inward = geometry::add(inward,
                               geometry::cross(geometry::sub(w.point(face[1]), w.point(face[0])),
                                               geometry::sub(w.point(face[2]), w.point(face[0]))));
      }
    }
  }
  Vec3 centre = {0, 0, 0};
  double edge_sum = 0;
  for (int i = 0; i < 4; ++i) {
    centre = geometry::add(centre, geometry::scale(w.point(k[i]), 0.25));
    edge_sum += geometry::norm(geometry::sub(w.point(k[i]), w.point(k[(i + 1) % 4])));
  }
  const double n = geometry::norm(inward);
  if (n > 0) inward = geometry::scale(inward, 1 / n);

  const double old_lowest = lowest_quality(w, cavity);
  const double old_volume = total_volume(w, cavity);

  // The first start inside the cavity's kernel (every new tetrahedron
  // positive, the volume unchanged), going deeper below t's surface faces.
  const uint32_t p = w.add_point(centre);
  std::vector<Tet> joined;
  for (const auto& f : faces) joined.push_back({f[0], f[1], f[2], p});
  bool started = false;
  for (double depth : {0.0, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0}) {
    w.point(p) = geometry::add(centre, geometry::scale(inward, depth * edge_sum / 4));
    if (fills_same_region(w, joined, old_volume)) {
      started = true;
      break;
    }
  }
  if (!started) {
    w.drop_last_point();
    return false;
  }
  for (uint32_t c : cavity) w.remove(c);
  for (const Tet& tet : joined) w.add(tet, label);
  ImproveFigures scratch;
  smooth_vertex(w, p, scratch);
  if (lowest_quality(w, w.star(p)) > old_lowest) {
    ++figures.vertices_inserted;
    return true;
  }
  const std::vector<uint32_t> added = w.star(p);
  for (uint32_t a : added) w.remove(a);
  w.drop_last_point();
  for (uint32_t c : cavity) w.revive(c);
  return false;
}

// Tries the smallest cavity first: t and its face neighbours, then every
// tetrahedron around t's points.
bool insert_vertex(WorkMesh& w, uint32_t t, ImproveFigures& figures) {
  const int32_t label = w.label(t);
  const Tet k = w.tet(t);
  std::vector<uint32_t> near = {t};
  for (uint8_t across = 0; across < 4; ++across) {
    const auto [a, b, c] = inward_face(k, across);
    const auto neighbour = w.across(t, a, b, c);
    if (neighbour && w.label(*neighbour) == label) near.push_back(*neighbour);
  }
  if (insert_in_cavity(w, t, near, figures)) return true;
  std::vector<uint32_t> around;
  for (uint32_t v : k) {
    for (uint32_t c : w.star(v)) {
      if (w.label(c) == label) around.push_back(c);
    }
  }
  return insert_in_cavity(w, t, around, figures);
}

// True when some outer face (one with no tetrahedron across it) other than
// t's has the edge c-d.
bool edge_on_outer_face(const WorkMesh& w, uint32_t t, uint32_t c, uint32_t d) {
  for (uint32_t s : w.star(c)) {
    if (s == t || !w.has(s, d)) continue;
    for (uint32_t x : w.tet(s)) {
      if (x != c && x != d && !w.across(s, c, d, x)) return true;
    }
  }
  return false;
}

// Peels sliver t = a,b,c,d off the surface when its faces a,b,c and a,b,d
// are outer faces folding over edge a-b and its faces a,c,d and b,c,d border
// tetrahedra of its label: those two faces become the surface, folding over
// c-d instead. It is refused when c-d is already an edge of the surface (the
// surface would stop being a manifold there), when the sliver is thicker
// than the peel depth, measured between its edges a-b and c-d, and when it
// shares a point with a sliver peeled before: peels never stack, so nowhere
// does the surface move further than the peel depth.
bool peel_sliver(WorkMesh& w, uint32_t t, ImproveFigures& figures) {
  if (!(w.max_peel_depth > 0) ||
      quality::categorize(w.plain_q(t)) == quality::QualityCategory::kGood) {
    return false;
  }
  const Tet k = w.tet(t);
  for (uint32_t v : k) {
    if (w.peeled(v)) return false;
  }
  std::vector<uint32_t> on_outer_faces, on_inner_faces;
  for (uint8_t across = 0; across < 4; ++across) {
    const auto [x, y, z] = inward_face(k, across);
    const auto neighbour = w.across(t, x, y, z);
    // The point opposite an outer face is on the other outer face only.
    if (!neighbour) {
      on_outer_faces.push_back(k[across]);
    } else if (w.label(*neighbour) == w.label(t)) {
      on_inner_faces.push_back(k[across]);
    }
  }
  if (on_outer_faces.size() != 2 || on_inner_faces.size() != 2) return false;
  const uint32_t a = on_inner_faces[0], b = on_inner_faces[1];
  const uint32_t c = on_outer_faces[0], d = on_outer_faces[1];
  if (edge_on_outer_face(w, t, c, d)) return false;
  const double volume = w.volume_of(k);
  const Vec3 across_edges =
      geometry::cross(geometry::sub(w.point(b), w.point(a)), geometry::sub(w.point(d), w.point(c)));
  const double depth = 6 * volume / geometry::norm(across_edges);
  if (!(depth <= w.max_peel_depth)) return false;
  w.remove(t);
  for (uint32_t v : k) w.mark_peeled(v);
  ++figures.slivers_peeled;
  figures.peeled_volume_mm3 += volume;
  figures.peel_depth_mm = std::max(figures.peel_depth_mm, depth);
  return true;
}

// One attempt to lift tetrahedron t: flips first (they change the
// connectivity that smoothing cannot), then its interior points.
bool improve_around(WorkMesh& w, uint32_t t, ImproveFigures& figures) {
  const Tet k = w.tet(t);
  static constexpr std::array<std::array<int, 2>, 6> kEdges = {
      {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  for (const auto& e : kEdges) {
    if (flip_3_2(w, k[e[0]], k[e[1]], figures)) return true;
  }
  for (int face = 0; face < 4; ++face) {
    if (flip_2_3(w, t, face, figures)) return true;
  }
  bool moved = false;
  for (uint32_t v : k) moved |= smooth_vertex(w, v, figures);
  if (moved) return true;
  return insert_vertex(w, t, figures) || peel_sliver(w, t, figures);
}

}  // namespace

absl::Status improve_tet_mesh(TetMesh& mesh, const ImproveParams& params, const RunContext& context,
                              ImproveFigures& figures) {
  const auto start = std::chrono::steady_clock::now();
  figures = ImproveFigures{};
  WorkMesh w(mesh, params);
  auto lowest_alive = [&w] {
    double lowest = kNone;
    for (uint32_t t = 0; t < w.size(); ++t) {
      if (w.alive(t)) lowest = std::min(lowest, w.plain_q(t));
    }
    return lowest;
  };
  figures.quality_min_before = lowest_alive();
  absl::Status status = absl::OkStatus();
  for (int sweep = 0; sweep < params.max_sweeps; ++sweep) {
    if (status = context.check_stop(); !status.ok()) break;
    std::vector<std::pair<double, uint32_t>> bad;
    for (uint32_t t = 0; t < w.size(); ++t) {
      if (w.alive(t) && w.quality(t) < params.target_quality) bad.emplace_back(w.quality(t), t);
    }
    if (bad.empty()) break;
    std::sort(bad.begin(), bad.end());
    ++figures.sweeps;
    bool changed = false;
    for (const auto& [q, t] : bad) {
      if (!w.alive(t) || w.quality(t) >= params.target_quality) continue;
      changed |= improve_around(w, t, figures);
    }
    if (!changed) break;
  }
  figures.quality_min_after = lowest_alive();
  w.write_back();
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status;
}

}  // namespace labelmesh::volume_mesh
