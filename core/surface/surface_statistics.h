// SPDX-License-Identifier: AGPL-3.0-or-later
// Statistics of a triangle surface: the paper's Table 2 (nodes, triangles,
// min and max angle) plus the topology and geometry checks a mesher needs.
#pragma once

#include <cstdint>

#include "core/surface/triangle_mesh.h"

namespace labelmesh::surface {

// The smallest angle the paper's surfaces keep, degrees.
inline constexpr double kWellShapedDeg = 30;

struct SurfaceStatistics {
  uint32_t nodes = 0;
  uint32_t triangles = 0;
  // Smallest and largest interior angle over all triangles, degrees.
  double min_angle_deg = 0;
  double max_angle_deg = 0;
  // Triangles with an angle below kWellShapedDeg (the name says 30: the
  // two change together).
  uint32_t triangles_below_30_deg = 0;
  // Edges with one incident triangle.
  uint32_t boundary_edges = 0;
  // Edges with three or more incident triangles.
  uint32_t non_manifold_edges = 0;
  // Vertices whose incident triangles form more than one fan.
  uint32_t non_manifold_vertices = 0;
  bool closed = false;    // no boundary edges
  bool manifold = false;  // no non-manifold edges or vertices
  // Every edge of two triangles runs opposite ways in them: the triangles
  // are wound alike.
  bool consistently_wound = false;
  // V - E + F over the used vertices: 2 per sphere-like component.
  int64_t euler_characteristic = 0;
  // Connected components (through shared vertices).
  uint32_t components = 0;
  // Signed enclosed volume, mm^3: positive when the surface faces outwards.
  double volume_mm3 = 0;
  double area_mm2 = 0;
};

// O(T log T) in the number of triangles.
SurfaceStatistics compute_surface_statistics(const TriangleMesh& mesh);

// True when the triangles can be one halfedge mesh: each has three distinct
// points, no directed edge is used twice (so every edge has at most two
// triangles, wound oppositely), and the triangles around each point form a
// single fan. CGAL's is_polygon_soup_a_polygon_mesh checks the same, but with
// ordered sets: about six times slower on the liver's 651 k triangles.
bool is_oriented_manifold(const TriangleMesh& mesh);

// Signed volume enclosed by the surface (divergence theorem), mm^3.
double signed_volume(const TriangleMesh& mesh);

// Sum of the triangles' areas, mm^2.
double surface_area(const TriangleMesh& mesh);

}  // namespace labelmesh::surface
