// SPDX-License-Identifier: AGPL-3.0-or-later
// The triangles of an indexed triangle soup that cross each other, found with
// a grid of their boxes and CGAL's exact predicates. Unlike
// count_self_intersections (surface_checks.h) the soup need not be a 2-manifold:
// edges may join any number of triangles, as in a multi-label surface net.
// The rules are CGAL's (Polygon_mesh_processing::self_intersections):
// triangles sharing an edge cross when they fold onto each other; sharing one
// point, when the edge opposite it in either one meets the other; otherwise
// when they meet at all. A degenerate triangle is paired with itself.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace labelmesh::surface {

// Crossing pairs as triangle indices, the smaller first; sorted.
using TrianglePairs = std::vector<std::pair<uint32_t, uint32_t>>;

// Every crossing pair of `triangles` (indices into `points`, LPS mm).
TrianglePairs crossing_triangles(const std::vector<std::array<double, 3>>& points,
                                 const std::vector<std::array<uint32_t, 3>>& triangles);

// Only the crossing pairs with at least one triangle in `among` (indices into
// `triangles`, any order): what changed where a few triangles moved.
TrianglePairs crossing_triangles_near(const std::vector<std::array<double, 3>>& points,
                                      const std::vector<std::array<uint32_t, 3>>& triangles,
                                      const std::vector<uint32_t>& among);

}  // namespace labelmesh::surface
