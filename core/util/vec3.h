// SPDX-License-Identifier: AGPL-3.0-or-later
// The few vector operations plain-array geometry code needs; CGAL code uses
// CGAL's own kernel types instead.
#pragma once

#include <array>
#include <cmath>

namespace labelmesh::geometry {

using Vec3 = std::array<double, 3>;

inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
// Angle between two vectors, radians; robust near 0 and pi, 0 when either
// is zero.
inline double angle_between(const Vec3& u, const Vec3& v) {
  return std::atan2(norm(cross(u, v)), dot(u, v));
}

}  // namespace labelmesh::geometry
