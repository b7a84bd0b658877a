// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/thin_shapes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/volume/phantom_grid.h"

namespace labelmesh::volume {
namespace {

using std::numbers::pi;
using Point = std::array<double, 3>;

Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Point& a) { return std::sqrt(dot(a, a)); }

// Distance from `p` to the segment a-b.
double segment_distance(const Point& p, const Point& a, const Point& b) {
  const Point ab = sub(b, a), ap = sub(p, a);
  const double t = std::clamp(dot(ap, ab) / dot(ab, ab), 0.0, 1.0);
  return norm(sub(ap, {ab[0] * t, ab[1] * t, ab[2] * t}));
}

// A tube of `radius` around a polyline, with a box around it to skip far points.
struct Tube {
  std::vector<Point> line;
  double radius = 0;
  Point low{}, high{};

  Tube(std::vector<Point> points, double r) : line(std::move(points)), radius(r) {
    low = high = line.front();
    for (const auto& p : line) {
      for (int a = 0; a < 3; ++a) {
        low[a] = std::min(low[a], p[a] - r);
        high[a] = std::max(high[a], p[a] + r);
      }
    }
  }
  bool contains(const Point& p) const {
    for (int a = 0; a < 3; ++a) {
      if (p[a] < low[a] || p[a] > high[a]) return false;
    }
    for (size_t i = 0; i + 1 < line.size(); ++i) {
      if (segment_distance(p, line[i], line[i + 1]) <= radius) return true;
    }
    return false;
  }
};

// `count` points of `curve(t)` for t in [0, 1].
template <typename F>
std::vector<Point> sampled(F&& curve, int count) {
  std::vector<Point> points;
  for (int i = 0; i <= count; ++i) points.push_back(curve(double(i) / count));
  return points;
}

}  // namespace

const std::vector<ThinShape>& thin_shapes() {
  static const std::vector<ThinShape> kShapes{
      {1, "straight tube 1 voxel across"},
      {2, "straight tube 2 voxels across"},
      {3, "straight tube 4 voxels across"},
      {4, "torus 3 voxels across (rib)"},
      {5, "helix 3 voxels across (vessel)"},
      {6, "arc-shaped tube 2 voxels across"},
      {7, "flat plate 1 voxel thick"},
      {8, "curved plate 2 voxels thick"},
      {9, "single voxel"},
      {10, "two voxels"},
      {11, "tube 3 voxels across cut by the volume's edge"}};
  return kShapes;
}

Phantom make_thin_shapes(const std::array<double, 3>& spacing) {
  // u: one voxel of the coarsest axis; the scene is 48 x 40 x 26 u.
  const double u = std::max({spacing[0], spacing[1], spacing[2]});
  ImageGeometry g;
  for (int a = 0; a < 3; ++a) g.spacing[a] = spacing[a];
  const Point extent{48 * u, 40 * u, 26 * u};
  for (int a = 0; a < 3; ++a) g.dims[a] = int64_t(std::floor(extent[a] / spacing[a])) + 1;
  auto at = [u](double x, double y, double z) { return Point{x * u, y * u, z * u}; };

  // Off-axis directions, so no tube lies along a grid line.
  std::vector<Tube> tubes;
  tubes.emplace_back(std::vector<Point>{at(3, 3.3, 4.1), at(19, 7.1, 6.2)}, 0.5 * u);
  tubes.emplace_back(std::vector<Point>{at(3, 9.2, 4.3), at(19, 12.9, 7.4)}, 1.0 * u);
  tubes.emplace_back(std::vector<Point>{at(4, 16.1, 5.2), at(19, 19.8, 9.3)}, 2.0 * u);
  const Point torus_centre = at(33.2, 10.3, 7.1);
  tubes.emplace_back(sampled(
                         [&](double t) {
                           const double a = 2 * pi * t;
                           // A ring of radius 8 u tilted about x by 20 degrees.
                           const double c = std::cos(20 * pi / 180), s = std::sin(20 * pi / 180);
                           const double x = 8 * std::cos(a), y = 8 * std::sin(a);
                           return Point{torus_centre[0] + x * u, torus_centre[1] + y * c * u,
                                        torus_centre[2] + y * s * u};
                         },
                         160),
                     1.5 * u);
  const Point helix_base = at(10.2, 30.1, 4.0);
  tubes.emplace_back(sampled(
                         [&](double t) {
                           const double a = 2.5 * 2 * pi * t;
                           return Point{helix_base[0] + 4.5 * std::cos(a) * u,
                                        helix_base[1] + 4.5 * std::sin(a) * u,
                                        helix_base[2] + 16 * t * u};
                         },
                         300),
                     1.5 * u);
  tubes.emplace_back(sampled(
                         [&](double t) {
                           const double a = pi * (0.1 + 0.8 * t);
                           return at(28 + 9 * std::cos(a), 24 + 9 * std::sin(a), 14 + 3 * t);
                         },
                         120),
                     1.0 * u);
  // Runs from inside past the far x face of the volume.
  tubes.emplace_back(std::vector<Point>{at(38.0, 33.2, 18.3), at(52, 35.1, 20.4)}, 1.5 * u);
  const int32_t tube_labels[] = {1, 2, 3, 4, 5, 6, 11};

  // The flat plate: 14 x 12 u, 1 u thick, in an oblique plane.
  const Point plate_centre = at(40.1, 22.3, 12.2);
  Point plate_normal{0.25, 0.2, 1.0};
  const double n = norm(plate_normal);
  for (auto& c : plate_normal) c /= n;
  const Point plate_e1 = [&] {
    Point e{1, 0, -plate_normal[0] / plate_normal[2]};
    const double m = norm(e);
    return Point{e[0] / m, e[1] / m, e[2] / m};
  }();
  const Point plate_e2{plate_normal[1] * plate_e1[2] - plate_normal[2] * plate_e1[1],
                       plate_normal[2] * plate_e1[0] - plate_normal[0] * plate_e1[2],
                       plate_normal[0] * plate_e1[1] - plate_normal[1] * plate_e1[0]};
  // The curved plate: a 2 u thick shell of a cylinder of radius 10 u about z,
  // 130 degrees of it, 10 u high.
  const Point shell_axis = at(26.3, 8.2, 14.0);

  auto label_at = [&](const Point& p) -> int {
    for (size_t i = 0; i < tubes.size(); ++i) {
      if (tubes[i].contains(p)) return tube_labels[i];
    }
    const Point d = sub(p, plate_centre);
    if (std::abs(dot(d, plate_normal)) <= 0.5 * u && std::abs(dot(d, plate_e1)) <= 7 * u &&
        std::abs(dot(d, plate_e2)) <= 6 * u)
      return 7;
    const double dx = p[0] - shell_axis[0], dy = p[1] - shell_axis[1];
    const double r = std::sqrt(dx * dx + dy * dy), angle = std::atan2(dy, dx);
    if (std::abs(r - 10 * u) <= 1.0 * u && angle > pi * 0.6 && angle < pi * 0.6 + 130 * pi / 180 &&
        std::abs(p[2] - shell_axis[2]) <= 5 * u)
      return 8;
    return 0;
  };
  Phantom phantom;
  phantom.volume = rasterise(g, label_at);
  // One voxel, and two side by side, set by index far from everything else.
  auto* labels = static_cast<uint8_t*>(phantom.volume.voxels->GetScalarPointer());
  auto set = [&](const Point& point, uint8_t label) {
    const auto index = g.to_index(point);
    int64_t i[3];
    for (int a = 0; a < 3; ++a) i[a] = std::llround(index[a]);
    labels[(i[2] * g.dims[1] + i[1]) * g.dims[0] + i[0]] = label;
  };
  set(at(44, 4, 22), 9);
  set(at(44, 8, 22), 10);
  set(at(44 + spacing[0] / u, 8, 22), 10);
  phantom.centre = {extent[0] / 2, extent[1] / 2, extent[2] / 2};

  const double voxel = g.voxel_volume();
  auto capsule = [&](const Tube& t) {
    const double length = norm(sub(t.line.back(), t.line.front()));
    return pi * t.radius * t.radius * length + 4.0 / 3.0 * pi * std::pow(t.radius, 3);
  };
  phantom.truth = {{1, capsule(tubes[0]), 0},
                   {2, capsule(tubes[1]), 0},
                   {3, capsule(tubes[2]), 0},
                   {4, 2 * pi * pi * 8 * u * std::pow(1.5 * u, 2), 4 * pi * pi * 8 * u * 1.5 * u},
                   {7, 14 * 12 * u * u * u, 0},
                   {9, voxel, 0},
                   {10, 2 * voxel, 0}};
  return phantom;
}

}  // namespace labelmesh::volume
