// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/phantom.h"

#include <cmath>
#include <numbers>

#include "core/volume/phantom_grid.h"
#include "core/volume/thin_shapes.h"

namespace labelmesh::volume {
namespace {

using std::numbers::pi;

constexpr std::array<double, 9> kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};

// Rotation by `degrees` about the unit vector along `axis` (Rodrigues).
std::array<double, 9> rotation(std::array<double, 3> axis, double degrees) {
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const double x = axis[0] / n, y = axis[1] / n, z = axis[2] / n;
  const double c = std::cos(degrees * pi / 180), s = std::sin(degrees * pi / 180), t = 1 - c;
  return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y, t * x * y + s * z, t * y * y + c,
          t * y * z - s * x, t * x * z - s * y, t * y * z + s * x, t * z * z + c};
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

int64_t cells_for(double length) { return static_cast<int64_t>(std::ceil(length)) + 6; }

// An off-grid centre, so that no symmetry of the grid hides an error.
constexpr std::array<double, 3> kCentre{0.31, -0.17, 0.23};

}  // namespace

std::optional<PhantomShape> phantom_shape_from_name(std::string_view name) {
  if (name == "sphere") return PhantomShape::kSphere;
  if (name == "nested-spheres") return PhantomShape::kNestedSpheres;
  if (name == "torus") return PhantomShape::kTorus;
  if (name == "boxes") return PhantomShape::kTouchingBoxes;
  if (name == "oblique-ellipsoid") return PhantomShape::kObliqueEllipsoid;
  if (name == "thin-shapes") return PhantomShape::kThinShapes;
  if (name == "thin-shapes-anisotropic") return PhantomShape::kThinShapesAnisotropic;
  return std::nullopt;
}

const std::vector<std::string_view>& phantom_shape_names() {
  static const std::vector<std::string_view> kNames{
      "sphere",      "nested-spheres",         "torus", "boxes", "oblique-ellipsoid",
      "thin-shapes", "thin-shapes-anisotropic"};
  return kNames;
}

Phantom make_phantom(PhantomShape shape, double scale) {
  if (shape == PhantomShape::kThinShapes)
    return make_thin_shapes({3 * scale, 3 * scale, 3 * scale});
  if (shape == PhantomShape::kThinShapesAnisotropic)
    return make_thin_shapes({0.75 * scale, 0.75 * scale, 3 * scale});
  Phantom phantom;
  phantom.centre = kCentre;
  const auto& c = phantom.centre;
  switch (shape) {
    case PhantomShape::kSphere: {
      const double r = 20 * scale;
      const int64_t n = cells_for(2 * r);
      const auto g = centred_grid({n, n, n}, {1, 1, 1}, kIdentity, c);
      phantom.volume = rasterise(g, [&](const auto& p) { return distance(p, c) <= r ? 1 : 0; });
      phantom.truth = {{1, 4.0 / 3.0 * pi * r * r * r, 4 * pi * r * r}};
      break;
    }
    case PhantomShape::kNestedSpheres: {
      const double r1 = 6 * scale, r2 = 12 * scale, r3 = 18 * scale;
      const int64_t n = cells_for(2 * r3);
      const auto g = centred_grid({n, n, n}, {1, 1, 1}, kIdentity, c);
      phantom.volume = rasterise(g, [&](const auto& p) {
        const double d = distance(p, c);
        return d < r1 ? 1 : d < r2 ? 2 : d < r3 ? 3 : 0;
      });
      auto ball = [](double r) { return 4.0 / 3.0 * pi * r * r * r; };
      auto sphere = [](double r) { return 4 * pi * r * r; };
      phantom.truth = {{1, ball(r1), sphere(r1)},
                       {2, ball(r2) - ball(r1), sphere(r2) + sphere(r1)},
                       {3, ball(r3) - ball(r2), sphere(r3) + sphere(r2)}};
      break;
    }
    case PhantomShape::kTorus: {
      const double major = 14 * scale, minor = 6 * scale;
      const int64_t n = cells_for(2 * (major + minor)), nz = cells_for(2 * minor);
      const auto g = centred_grid({n, n, nz}, {1, 1, 1}, kIdentity, c);
      phantom.volume = rasterise(g, [&](const auto& p) {
        const double x = p[0] - c[0], y = p[1] - c[1], z = p[2] - c[2];
        const double ring = std::sqrt(x * x + y * y) - major;
        return ring * ring + z * z <= minor * minor ? 1 : 0;
      });
      phantom.truth = {{1, 2 * pi * pi * major * minor * minor, 4 * pi * pi * major * minor}};
      break;
    }
    case PhantomShape::kTouchingBoxes: {
      // Box sides in whole voxels, so the voxel volume is exact.
      const auto side = [&](double v) { return std::round(v * scale); };
      const double a = side(16), b = side(20), h = side(24);
      const int64_t n = cells_for(2 * a), m = cells_for(b), l = cells_for(h);
      ImageGeometry g;
      g.dims = {n, m, l};
      phantom.centre = {3 + a, 3 + b / 2, 3 + h / 2};
      phantom.volume = rasterise(g, [&](const auto& p) {
        if (p[1] < 3 || p[1] >= 3 + b || p[2] < 3 || p[2] >= 3 + h) return 0;
        if (p[0] >= 3 && p[0] < 3 + a) return 1;
        if (p[0] >= 3 + a && p[0] < 3 + 2 * a) return 2;
        return 0;
      });
      const double volume = a * b * h, area = 2 * (a * b + b * h + a * h);
      phantom.truth = {{1, volume, area}, {2, volume, area}};
      break;
    }
    case PhantomShape::kObliqueEllipsoid: {
      const double ax = 18 * scale, ay = 12 * scale, az = 9 * scale;
      const std::array<double, 3> spacing{0.8, 1.1, 1.7};
      const std::array<int64_t, 3> dims{cells_for(2 * (ax + 3) / spacing[0]),
                                        cells_for(2 * (ax + 3) / spacing[1]),
                                        cells_for(2 * (ax + 3) / spacing[2])};
      phantom.centre = {-30.0, 12.5, 45.25};
      const auto g = centred_grid(dims, spacing, rotation({1, 2, 3}, 25), phantom.centre);
      const auto& e = phantom.centre;
      phantom.volume = rasterise(g, [&](const auto& p) {
        const double x = (p[0] - e[0]) / ax, y = (p[1] - e[1]) / ay, z = (p[2] - e[2]) / az;
        return x * x + y * y + z * z <= 1 ? 1 : 0;
      });
      // Knud Thomsen's approximation of the ellipsoid's area (error < 1.061 %).
      const double q = 1.6075;
      const double area =
          4 * pi *
          std::pow((std::pow(ax * ay, q) + std::pow(ax * az, q) + std::pow(ay * az, q)) / 3, 1 / q);
      phantom.truth = {{1, 4.0 / 3.0 * pi * ax * ay * az, area}};
      break;
    }
    case PhantomShape::kThinShapes:
    case PhantomShape::kThinShapesAnisotropic:
      break;
  }
  return phantom;
}

}  // namespace labelmesh::volume
