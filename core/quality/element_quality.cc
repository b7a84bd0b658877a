// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/quality/element_quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace labelmesh::quality {
namespace {

using geometry::cross;
using geometry::dot;
using geometry::norm;
using geometry::sub;

// The paper prints 8.47867 for A_gamma's constant, which gives a regular tetrahedron
// A_gamma ≈ 1.0008 rather than 1. 6√2 is the exact value (V = l³/(6√2) for a regular tetrahedron
// of edge l) and is the constant Verdict and VTK use for aspect gamma, so Q matches their figure.
constexpr double kAspectGammaConstant = 6.0 * std::numbers::sqrt2;

// tetra_quality of each corner tetrahedron of the ideal pyramid (unit square base, unit apex
// edges): edges² sum to 7, V = 1/(6√2), hence Q = (6/7)^(3/2).
const double kIdealPyramidCornerQuality = std::pow(6.0 / 7.0, 1.5);

double triple(const Point& a, const Point& b, const Point& c) { return dot(cross(a, b), c); }

// Dihedral angle along edge (a, b) between the faces (a, b, c) and (a, b, d), in radians. Both
// face normals are perpendicular to the edge, so their angle is the dihedral angle; atan2 keeps it
// accurate near 0° and 180°, where acos of a dot product loses half the digits.
double dihedral_rad(const Point& a, const Point& b, const Point& c, const Point& d) {
  const Point edge = sub(b, a);
  const Point n1 = cross(edge, sub(c, a));
  const Point n2 = cross(edge, sub(d, a));
  return std::atan2(norm(cross(n1, n2)), dot(n1, n2));
}

}  // namespace

double tetra_signed_volume(const Tet& p) {
  return triple(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])) / 6.0;
}

double tetra_quality(const Tet& p) {
  double sum_sq = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const Point e = sub(p[j], p[i]);
      sum_sq += dot(e, e);
    }
  }
  if (sum_sq == 0.0) return 0.0;
  const double l_rms = std::sqrt(sum_sq / 6.0);
  return kAspectGammaConstant * tetra_signed_volume(p) / (l_rms * l_rms * l_rms);
}

std::pair<double, double> tetra_dihedral_range_deg(const Tet& p) {
  // Each edge (i, j) with the two nodes (k, l) not on it.
  static constexpr int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                       {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  double lo = std::numbers::pi;
  double hi = 0.0;
  for (const auto& e : kEdges) {
    const double angle = dihedral_rad(p[e[0]], p[e[1]], p[e[2]], p[e[3]]);
    lo = std::min(lo, angle);
    hi = std::max(hi, angle);
  }
  constexpr double kDeg = 180.0 / std::numbers::pi;
  return {lo * kDeg, hi * kDeg};
}

double jacobian_ratio(std::span<const double> corner_jacobians) {
  if (corner_jacobians.empty()) return -1.0;
  const auto [lo, hi] = std::minmax_element(corner_jacobians.begin(), corner_jacobians.end());
  if (!(*hi > 0.0)) return -1.0;
  return *lo / *hi;
}

HexCorners hexahedron_corners(const Hex& p) {
  // VTK node at parametric corner (r, s, t) ∈ {0,1}³.
  static constexpr int kNode[2][2][2] = {{{0, 4}, {3, 7}}, {{1, 5}, {2, 6}}};
  HexCorners corners{};
  for (int r = 0; r < 2; ++r) {
    for (int s = 0; s < 2; ++s) {
      for (int t = 0; t < 2; ++t) {
        const Point dr = sub(p[kNode[1][s][t]], p[kNode[0][s][t]]);
        const Point ds = sub(p[kNode[r][1][t]], p[kNode[r][0][t]]);
        const Point dt = sub(p[kNode[r][s][1]], p[kNode[r][s][0]]);
        corners.jacobian[kNode[r][s][t]] = triple(dr, ds, dt);
        corners.edge_lengths[kNode[r][s][t]] = norm(dr) * norm(ds) * norm(dt);
      }
    }
  }
  return corners;
}

std::array<double, 8> hexahedron_corner_jacobians(const Hex& p) {
  return hexahedron_corners(p).jacobian;
}

double hexahedron_jacobian_ratio(const Hex& p) {
  return jacobian_ratio(hexahedron_corner_jacobians(p));
}

double hexahedron_scaled_jacobian(const Hex& p) {
  const HexCorners corners = hexahedron_corners(p);
  double lowest = 1.0;
  for (int k = 0; k < 8; ++k) {
    if (!(corners.edge_lengths[k] > 0.0)) return 0.0;
    lowest = std::min(lowest, corners.jacobian[k] / corners.edge_lengths[k]);
  }
  return lowest;
}

std::array<double, 6> wedge_corner_jacobians(const Wedge& p) {
  std::array<double, 6> jacobians{};
  for (int node = 0; node < 6; ++node) {
    const int v = node % 3;
    const int base = node - v;  // first node of this node's triangle
    const int next = base + (v + 1) % 3;
    const int prev = base + (v + 2) % 3;
    const int across = (node + 3) % 6;  // the node at the other end of the vertical edge
    const Point to_next = sub(p[next], p[node]);
    const Point to_prev = sub(p[prev], p[node]);
    const Point vertical = sub(p[across], p[node]);
    // Both triangles wind clockwise seen from the top, so the bottom needs (prev, next) to point
    // its normal up the vertical edge, and the top (next, prev) to point it down.
    jacobians[node] =
        node < 3 ? triple(to_prev, to_next, vertical) : triple(to_next, to_prev, vertical);
  }
  return jacobians;
}

double wedge_jacobian_ratio(const Wedge& p) { return jacobian_ratio(wedge_corner_jacobians(p)); }

std::array<double, 4> pyramid_corner_jacobians(const Pyramid& p) {
  std::array<double, 4> jacobians{};
  for (int i = 0; i < 4; ++i) {
    const Point& corner = p[i];
    jacobians[i] =
        triple(sub(p[(i + 1) % 4], corner), sub(p[(i + 3) % 4], corner), sub(p[4], corner));
  }
  return jacobians;
}

double pyramid_jacobian_ratio(const Pyramid& p) {
  return jacobian_ratio(pyramid_corner_jacobians(p));
}

double pyramid_signed_aspect_ratio(const Pyramid& p) {
  double worst = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    worst = std::min(worst, tetra_quality({p[i], p[(i + 1) % 4], p[(i + 3) % 4], p[4]}));
  }
  return worst / kIdealPyramidCornerQuality;
}

QualityCategory categorize(double q) {
  // Written as !(q > x) so that NaN, from NaN coordinates, lands in kInvalid.
  if (!(q > 0.001)) return QualityCategory::kInvalid;
  if (q <= 1.0 / 30.0) return QualityCategory::kVeryBad;
  if (q <= 0.2) return QualityCategory::kQuestionable;
  return QualityCategory::kGood;
}

void QualitySummary::add(double q) {
  min = std::min(min, q);
  ++count;
  mean += (q - mean) / static_cast<double>(count);
  switch (categorize(q)) {
    case QualityCategory::kInvalid:
      ++invalid;
      break;
    case QualityCategory::kVeryBad:
      ++very_bad;
      break;
    case QualityCategory::kQuestionable:
      ++questionable;
      break;
    case QualityCategory::kGood:
      ++good;
      break;
  }
}

void QualitySummary::add_dihedral_range(std::pair<double, double> range_deg) {
  min_dihedral_deg = std::min(min_dihedral_deg, range_deg.first);
  max_dihedral_deg = std::max(max_dihedral_deg, range_deg.second);
}

void QualitySummary::merge(const QualitySummary& other) {
  if (other.count > 0) {
    const std::int64_t total = count + other.count;
    mean += (other.mean - mean) * static_cast<double>(other.count) / static_cast<double>(total);
    count = total;
  }
  min = std::min(min, other.min);
  invalid += other.invalid;
  very_bad += other.very_bad;
  questionable += other.questionable;
  good += other.good;
  min_dihedral_deg = std::min(min_dihedral_deg, other.min_dihedral_deg);
  max_dihedral_deg = std::max(max_dihedral_deg, other.max_dihedral_deg);
}

}  // namespace labelmesh::quality
