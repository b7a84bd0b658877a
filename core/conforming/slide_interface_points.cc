// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/slide_interface_points.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "core/conforming/check_conforming_mesh.h"
#include "core/quality/element_quality.h"
#include "core/util/status_macros.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;
using volume_mesh::TetMesh;

// Compressed lists: for each key, its items.
struct Lists {
  std::vector<uint32_t> start;
  std::vector<uint32_t> items;

  template <typename F>
  void for_each(uint32_t key, F&& f) const {
    for (uint32_t i = start[key]; i < start[key + 1]; ++i) f(items[i]);
  }
};

Lists make_lists(size_t keys, const std::vector<std::pair<uint32_t, uint32_t>>& pairs) {
  Lists lists;
  lists.start.assign(keys + 1, 0);
  for (const auto& [key, item] : pairs) ++lists.start[key + 1];
  for (size_t k = 0; k < keys; ++k) lists.start[k + 1] += lists.start[k];
  lists.items.resize(pairs.size());
  std::vector<uint32_t> next(lists.start.begin(), lists.start.end() - 1);
  for (const auto& [key, item] : pairs) lists.items[next[key]++] = item;
  return lists;
}

quality::Tet corners(const TetMesh& mesh, uint32_t t) {
  const auto& v = mesh.tetrahedra[t];
  return {mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]], mesh.points[v[3]]};
}

// One number per tetrahedron that both targets raise: Q, or the smallest
// dihedral angle over 45 degrees when that is lower. Not above 0 when flat
// or inverted.
double score(const TetMesh& mesh, uint32_t t) {
  const quality::Tet tet = corners(mesh, t);
  const double q = quality::tetra_quality(tet);
  if (q <= 0) return q;
  return std::min(q, quality::tetra_dihedral_range_deg(tet).first / 45.0);
}

bool below_target(const TetMesh& mesh, uint32_t t, const SlideParams& params) {
  const quality::Tet tet = corners(mesh, t);
  return quality::tetra_quality(tet) < params.target_quality ||
         quality::tetra_dihedral_range_deg(tet).first < params.target_dihedral_deg;
}

Vec3 face_normal(const TetMesh& mesh, const volume_mesh::InterfaceFace& face) {
  const Vec3& a = mesh.points[face.points[0]];
  return geometry::cross(geometry::sub(mesh.points[face.points[1]], a),
                         geometry::sub(mesh.points[face.points[2]], a));
}

Vec3 unit(const Vec3& v) {
  const double n = geometry::norm(v);
  return n > 0 ? geometry::scale(v, 1 / n) : Vec3{0, 0, 0};
}

class Slider {
 public:
  Slider(TetMesh& mesh, size_t interface_points, const std::vector<Vec3>& anchor,
         const std::vector<double>& reach)
      : mesh_(mesh), anchor_(anchor), reach_(reach), faces_(volume_mesh::interface_faces(mesh)) {
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
      for (uint32_t p : mesh.tetrahedra[t]) {
        if (p < interface_points) pairs.push_back({p, static_cast<uint32_t>(t)});
      }
    }
    star_ = make_lists(interface_points, pairs);
    pairs.clear();
    // Per point, the label pairs of the faces around it (up to three) and
    // each pair's summed normal.
    std::vector<std::array<std::array<int32_t, 2>, 3>> pair_of(interface_points);
    std::vector<std::array<Vec3, 3>> normals(interface_points);
    std::vector<uint8_t> pair_count(interface_points, 0);
    for (size_t f = 0; f < faces_.size(); ++f) {
      const Vec3 n = face_normal(mesh, faces_[f]);
      face_normal_.push_back(unit(n));
      for (uint32_t p : faces_[f].points) {
        if (p >= interface_points) continue;
        pairs.push_back({p, static_cast<uint32_t>(f)});
        uint8_t& count = pair_count[p];
        uint8_t k = 0;
        while (k < count && k < 3 && pair_of[p][k] != faces_[f].labels) ++k;
        if (k == count && count < 4) ++count;
        if (k < 3) {
          pair_of[p][k] = faces_[f].labels;
          normals[p][k] = geometry::add(normals[p][k], n);
        }
      }
    }
    around_ = make_lists(interface_points, pairs);
    // On one interface a point slides in its tangent plane; where three
    // labels meet, along the junction curve (across both patches' normals);
    // where more meet, it stays.
    kind_.assign(interface_points, Kind::kFixed);
    direction_.assign(interface_points, {Vec3{0, 0, 0}, Vec3{0, 0, 0}});
    for (size_t p = 0; p < interface_points; ++p) {
      if (pair_count[p] == 1) {
        const Vec3 n = unit(normals[p][0]);
        if (geometry::norm(n) == 0) continue;
        const Vec3 helper = std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        const Vec3 t1 = unit(geometry::cross(n, helper));
        direction_[p] = {t1, geometry::cross(n, t1)};
        kind_[p] = Kind::kPlane;
      } else if (pair_count[p] == 2 || pair_count[p] == 3) {
        const Vec3 d = unit(geometry::cross(unit(normals[p][0]), unit(normals[p][1])));
        if (geometry::norm(d) == 0) continue;
        direction_[p] = {d, Vec3{0, 0, 0}};
        kind_[p] = Kind::kCurve;
      }
    }
  }

  const Lists& star() const { return star_; }

  // The worst score among the point's tetrahedra.
  double worst(uint32_t p) const {
    double w = 2;
    star_.for_each(p, [&](uint32_t t) { w = std::min(w, score(mesh_, t)); });
    return w;
  }

  bool faces_keep_their_sides(uint32_t p) const {
    bool ok = true;
    around_.for_each(p, [&](uint32_t f) {
      ok = ok && geometry::dot(unit(face_normal(mesh_, faces_[f])), face_normal_[f]) >=
                     std::cos(std::numbers::pi / 6);
    });
    return ok;
  }

  // Pattern search in the tangent plane (or along the junction curve) and,
  // with `off_fraction` > 0, off it by that fraction of the step; true when
  // the point moved.
  bool slide(uint32_t p, double off_fraction) {
    std::vector<Vec3> directions;
    const auto& [t1, t2] = direction_[p];
    if (kind_[p] == Kind::kPlane) {
      for (int k = 0; k < 8; ++k) {
        const double angle = k * 2 * std::numbers::pi / 8;
        directions.push_back(geometry::add(geometry::scale(t1, std::cos(angle)),
                                           geometry::scale(t2, std::sin(angle))));
      }
    } else if (kind_[p] == Kind::kCurve) {
      directions = {t1, geometry::scale(t1, -1)};
    }
    if (off_fraction > 0) {
      for (const Vec3& off : off_directions(p)) {
        directions.push_back(geometry::scale(off, off_fraction));
        directions.push_back(geometry::scale(off, -off_fraction));
      }
    }
    if (directions.empty()) return false;
    double length = 0;
    int edges = 0;
    star_.for_each(p, [&](uint32_t t) {
      for (uint32_t q : mesh_.tetrahedra[t]) {
        if (q == p) continue;
        length += geometry::norm(geometry::sub(mesh_.points[q], mesh_.points[p]));
        ++edges;
      }
    });
    if (edges == 0) return false;
    length /= edges;

    Vec3& position = mesh_.points[p];
    const Vec3 start = position;
    double best = worst(p);
    for (double step : {0.3, 0.15, 0.075, 0.03, 0.01}) {
      for (int round = 0; round < 6; ++round) {
        const Vec3 from = position;
        Vec3 chosen = from;
        for (const Vec3& direction : directions) {
          const Vec3 candidate = geometry::add(from, geometry::scale(direction, step * length));
          if (geometry::norm(geometry::sub(candidate, anchor_[p])) > reach_[p]) continue;
          position = candidate;
          const double w = worst(p);
          if (w > best + 1e-9 && faces_keep_their_sides(p)) {
            best = w;
            chosen = candidate;
          }
          position = from;
        }
        if (chosen == from) break;
        position = chosen;
      }
    }
    return position != start;
  }

 private:
  // Unit directions across the point's own directions: the normal on one
  // interface, two across a junction curve, three axes where curves meet.
  std::vector<Vec3> off_directions(uint32_t p) const {
    const auto& [t1, t2] = direction_[p];
    if (kind_[p] == Kind::kPlane) return {geometry::cross(t1, t2)};
    if (kind_[p] == Kind::kCurve) {
      const Vec3 helper = std::abs(t1[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
      const Vec3 u = unit(geometry::cross(t1, helper));
      return {u, geometry::cross(t1, u)};
    }
    return {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  }

  TetMesh& mesh_;
  const std::vector<Vec3>& anchor_;
  const std::vector<double>& reach_;
  std::vector<volume_mesh::InterfaceFace> faces_;
  std::vector<Vec3> face_normal_;
  Lists star_;
  Lists around_;
  enum class Kind : uint8_t { kFixed, kPlane, kCurve };
  std::vector<Kind> kind_;
  std::vector<std::array<Vec3, 2>> direction_;
};

std::vector<uint32_t> tetrahedra_below(const TetMesh& mesh, const SlideParams& params) {
  std::vector<uint32_t> below;
  for (uint32_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    if (below_target(mesh, t, params)) below.push_back(t);
  }
  return below;
}

}  // namespace

absl::Status slide_interface_points(TetMesh& mesh, size_t interface_points,
                                    const std::vector<std::array<double, 3>>& anchor,
                                    const std::vector<double>& reach, const SlideParams& params,
                                    const RunContext& context, SlideFigures& figures) {
  const auto start = std::chrono::steady_clock::now();
  figures = SlideFigures{};
  interface_points = std::min({interface_points, mesh.points.size(), anchor.size(), reach.size()});
  std::vector<uint32_t> below = tetrahedra_below(mesh, params);
  figures.tetrahedra_below_before = below.size();
  Slider slider(mesh, interface_points, anchor, reach);
  for (int sweep = 0; sweep < params.max_sweeps && !below.empty(); ++sweep) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    std::vector<uint32_t> points;
    for (uint32_t t : below) {
      for (uint32_t p : mesh.tetrahedra[t]) {
        if (p < interface_points) points.push_back(p);
      }
    }
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());
    // Only tetrahedra around moved points change: they and the ones below
    // before are measured again.
    std::vector<uint32_t> changed = below;
    size_t moved = 0;
    for (uint32_t p : points) {
      if (!slider.slide(p, params.off_fraction)) continue;
      ++moved;
      slider.star().for_each(p, [&](uint32_t t) { changed.push_back(t); });
    }
    figures.points_moved += moved;
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    below.clear();
    for (uint32_t t : changed) {
      if (below_target(mesh, t, params)) below.push_back(t);
    }
    if (moved == 0) break;
  }
  figures.tetrahedra_below_after = below.size();
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

}  // namespace labelmesh::conforming
