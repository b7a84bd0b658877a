// SPDX-License-Identifier: AGPL-3.0-or-later
// Where points lie against a closed surface: inside or outside, and how far
// from it. The mixed-element mesher asks this of every grid node and cell.
// CGAL's AABB tree and Side_of_triangle_mesh do the work, in
// surface_oracle.cc only (CGAL's compile cost stays there).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/surface/triangle_mesh.h"

namespace labelmesh::mixed_mesh {

class SurfaceOracle {
 public:
  // INVALID_ARGUMENT when `surface` is not a closed, oriented manifold.
  static absl::StatusOr<SurfaceOracle> build(const surface::TriangleMesh& surface);

  // Distance to the surface, mm: positive inside, negative outside. Safe to
  // call from several threads at once.
  double depth(const std::array<double, 3>& point) const;
  // depth() of each point, on up to `threads` threads.
  std::vector<double> depths(const std::vector<std::array<double, 3>>& points,
                             unsigned threads) const;
  // The nearest point of the surface.
  std::array<double, 3> closest(const std::array<double, 3>& point) const;
  // Where the ray from `from` along `direction` first meets the surface;
  // none when it misses (or `direction` is zero).
  std::optional<std::array<double, 3>> first_hit(const std::array<double, 3>& from,
                                                 const std::array<double, 3>& direction) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace labelmesh::mixed_mesh
