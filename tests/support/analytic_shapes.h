// SPDX-License-Identifier: AGPL-3.0-or-later
// Analytic shapes sampled onto coarse and anisotropic, possibly oblique,
// voxel grids, with their true surface: how far a mesh lies from it and how
// far its normals turn from the true ones.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include "core/surface/triangle_mesh.h"
#include "core/util/vec3.h"
#include "core/volume/label_volume.h"

namespace labelmesh::testing {

using geometry::Vec3;

// A closed shape centred at the origin (LPS mm).
struct AnalyticShape {
  std::string name;
  std::function<bool(const Vec3&)> inside;
  // Distance to the true surface, mm (first order for the ellipsoid).
  std::function<double(const Vec3&)> distance;
  // Outward unit normal of the true surface nearest the point.
  std::function<Vec3(const Vec3&)> normal;
  double extent_mm = 0;  // half the side of a box holding it
};

inline Vec3 unit(const Vec3& v) {
  const double n = geometry::norm(v);
  return n > 0 ? geometry::scale(v, 1 / n) : Vec3{0, 0, 1};
}

inline AnalyticShape sphere_shape(double r) {
  return {"sphere", [r](const Vec3& p) { return geometry::norm(p) < r; },
          [r](const Vec3& p) { return std::abs(geometry::norm(p) - r); },
          [](const Vec3& p) { return unit(p); }, r + 6};
}

inline AnalyticShape ellipsoid_shape(double a, double b, double c) {
  const auto g = [=](const Vec3& p) {
    return std::sqrt(p[0] * p[0] / (a * a) + p[1] * p[1] / (b * b) + p[2] * p[2] / (c * c));
  };
  const auto gradient = [=](const Vec3& p) {
    const double q = std::max(1e-12, g(p));
    return Vec3{p[0] / (a * a * q), p[1] / (b * b * q), p[2] / (c * c * q)};
  };
  return {"ellipsoid", [=](const Vec3& p) { return g(p) < 1; },
          [=](const Vec3& p) { return std::abs(g(p) - 1) / geometry::norm(gradient(p)); },
          [=](const Vec3& p) { return unit(gradient(p)); }, std::max({a, b, c}) + 6};
}

// A ring of radius `major` around z with a round cross-section of `minor`.
inline AnalyticShape torus_shape(double major, double minor, std::string name = "torus") {
  // From the nearest point of the ring: on the axis every ring point is as
  // near, so any will do (the axis is never inside).
  const auto tube = [=](const Vec3& p) {
    const double rho = std::hypot(p[0], p[1]);
    if (rho == 0) return Vec3{-major, 0, p[2]};
    const double scale = major / rho;
    return Vec3{p[0] - p[0] * scale, p[1] - p[1] * scale, p[2]};
  };
  return {std::move(name), [=](const Vec3& p) { return geometry::norm(tube(p)) < minor; },
          [=](const Vec3& p) { return std::abs(geometry::norm(tube(p)) - minor); },
          [=](const Vec3& p) { return unit(tube(p)); }, major + minor + 6};
}

// A round column of radius `r` about z, longer than any grid that samples it:
// its walls only, cut at the volume's edges as organs are by a CT slab.
inline AnalyticShape column_shape(double r) {
  return {"column", [r](const Vec3& p) { return std::hypot(p[0], p[1]) < r; },
          [r](const Vec3& p) { return std::abs(std::hypot(p[0], p[1]) - r); },
          [](const Vec3& p) {
            return unit(Vec3{p[0], p[1], 0});
          },
          r + 6};
}

// A grid of `spacing` voxels whose axes are rotated by `degrees` about
// (1, 1, 1) (0: axis-aligned), covering the shape, centred at the origin,
// or `shift_slices` of a slice off it along the third axis (a shape whose
// top lies exactly on a slice centre, where the voxels cannot place it,
// then ends between two).
inline volume::LabelVolume sample_shape(const AnalyticShape& shape,
                                        const std::array<double, 3>& spacing, double degrees = 0,
                                        double shift_slices = 0) {
  volume::LabelVolume v;
  auto& g = v.geometry;
  g.spacing = spacing;
  const double t = degrees * M_PI / 180, c = std::cos(t), s = std::sin(t), k = 1 - c;
  const double u = 1 / std::sqrt(3.0);  // rotation axis (u, u, u)
  g.direction = {c + u * u * k,     u * u * k - u * s, u * u * k + u * s,
                 u * u * k + u * s, c + u * u * k,     u * u * k - u * s,
                 u * u * k - u * s, u * u * k + u * s, c + u * u * k};
  // Rotated, the shape's box needs up to sqrt(3) times the half side.
  const double half = shape.extent_mm * (degrees != 0 ? 1.3 : 1.0);
  for (int a = 0; a < 3; ++a)
    g.dims[a] = 2 * static_cast<int64_t>(std::ceil(half / spacing[a])) + 1;
  // Index (dims - 1) / 2 sits at the origin.
  std::array<double, 3> offset{};
  for (int a = 0; a < 3; ++a) offset[a] = -0.5 * double(g.dims[a] - 1) * spacing[a];
  offset[2] += shift_slices * spacing[2];
  for (int r = 0; r < 3; ++r)
    g.origin[r] = g.direction[3 * r] * offset[0] + g.direction[3 * r + 1] * offset[1] +
                  g.direction[3 * r + 2] * offset[2];
  auto labels = vtkSmartPointer<vtkUnsignedCharArray>::New();
  labels->SetNumberOfTuples(g.dims[0] * g.dims[1] * g.dims[2]);
  int64_t n = 0;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x)
        labels->SetValue(n++,
                         shape.inside(g.to_physical({double(x), double(y), double(z)})) ? 1 : 0);
  v.voxels = vtkSmartPointer<vtkImageData>::New();
  v.voxels->SetDimensions(int(g.dims[0]), int(g.dims[1]), int(g.dims[2]));
  v.voxels->GetPointData()->SetScalars(labels);
  return v;
}

struct ShapeError {
  double rms_mm = 0;          // area-weighted, at triangle centroids
  double normal_p95_deg = 0;  // area-weighted 95th percentile
};

inline ShapeError shape_error(const surface::TriangleMesh& mesh, const AnalyticShape& shape) {
  struct Sample {
    double angle;
    double area;
  };
  std::vector<Sample> angles;
  double sum = 0, area_sum = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const Vec3 n = geometry::cross(geometry::sub(b, a), geometry::sub(c, a));
    const double area = 0.5 * geometry::norm(n);
    if (area == 0) continue;
    const Vec3 centroid = geometry::scale(geometry::add(a, geometry::add(b, c)), 1.0 / 3);
    const double d = shape.distance(centroid);
    sum += area * d * d;
    area_sum += area;
    const double cosine = std::clamp(geometry::dot(unit(n), shape.normal(centroid)), -1.0, 1.0);
    angles.push_back({std::acos(cosine) * 180 / M_PI, area});
  }
  ShapeError error;
  if (area_sum == 0) return error;
  error.rms_mm = std::sqrt(sum / area_sum);
  std::sort(angles.begin(), angles.end(),
            [](const Sample& x, const Sample& y) { return x.angle < y.angle; });
  double seen = 0;
  for (const auto& sample : angles) {
    seen += sample.area;
    if (seen >= 0.95 * area_sum) {
      error.normal_p95_deg = sample.angle;
      break;
    }
  }
  return error;
}

}  // namespace labelmesh::testing
