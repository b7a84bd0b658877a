// SPDX-License-Identifier: AGPL-3.0-or-later
// CGAL Polygon_mesh_processing repair: every defect is found and fixed by
// CGAL; this file only chooses the order and counts what changed.
#include "core/surface/surface_repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/util/exception_status.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::surface {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using cgal::Mesh;
using cgal::Point;

struct SharpCounts {
  uint32_t needles = 0;
  uint32_t caps = 0;
};

// A face that plain double arithmetic, with a wide margin for its rounding,
// shows to be neither a needle nor a cap. CGAL's exact predicates fall back
// to exact numbers whenever a comparison is close, and on Marching Cubes
// surfaces (right angles, equal edges) nearly every face is: this keeps them
// for the faces near a threshold, sparing a good share of the repair's time.
bool clearly_not_sharp(const Mesh& mesh, Mesh::Face_index f, double needle_ratio,
                       double cap_cosine) {
  constexpr double kMargin = 1e-9;
  std::array<Point, 3> p;
  int corner = 0;
  for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) p[corner++] = mesh.point(v);
  std::array<double, 3> squared;
  for (int i = 0; i < 3; ++i) squared[i] = CGAL::squared_distance(p[i], p[(i + 1) % 3]);
  const auto [shortest, longest] = std::minmax({squared[0], squared[1], squared[2]});
  if (!(shortest > 0)) return false;
  if (!(longest < needle_ratio * needle_ratio * shortest * (1 - kMargin))) return false;
  for (int i = 0; i < 3; ++i) {
    // The corner at p[i] between its two edges.
    const double dot = (p[(i + 1) % 3] - p[i]) * (p[(i + 2) % 3] - p[i]);
    const double scale = squared[i] * squared[(i + 2) % 3];
    const bool acute = dot > kMargin * std::sqrt(scale);
    const bool wide_of_cap = dot * dot < cap_cosine * cap_cosine * scale * (1 - kMargin);
    if (!acute && !wide_of_cap) return false;
  }
  return true;
}

SharpCounts count_sharp_triangles(const Mesh& mesh, const RepairParams& params) {
  const double cap_cosine = std::cos(params.cap_angle_deg * std::numbers::pi / 180);
  SharpCounts counts;
  for (auto f : mesh.faces()) {
    if (clearly_not_sharp(mesh, f, params.needle_ratio, cap_cosine)) continue;
    if (PMP::is_needle_triangle_face(f, mesh, params.needle_ratio) != Mesh::null_halfedge()) {
      ++counts.needles;
    } else if (PMP::is_cap_triangle_face(f, mesh, cap_cosine) != Mesh::null_halfedge()) {
      ++counts.caps;
    }
  }
  return counts;
}

// Soup stage: merges duplicate points, drops triangles with repeated corners,
// orients triangles consistently, giving each fan of a non-manifold vertex (or
// edge) its own copy of the point. Then builds the halfedge mesh.
absl::StatusOr<Mesh> mesh_from_soup(const TriangleMesh& input, RepairCounts& counts) {
  // Marching Cubes output is usually a valid mesh already: skip the soup pass.
  if (auto mesh = cgal::to_surface_mesh(input)) return std::move(*mesh);
  std::vector<Point> points = cgal::to_points(input);
  std::vector<std::vector<size_t>> polygons;
  polygons.reserve(input.triangles.size());
  for (const auto& t : input.triangles) polygons.push_back({t[0], t[1], t[2]});
  PMP::repair_polygon_soup(points, polygons);
  counts.degenerate_triangles_removed +=
      static_cast<uint32_t>(input.triangles.size() - polygons.size());
  const size_t points_before = points.size();
  PMP::orient_polygon_soup(points, polygons);
  counts.non_manifold_vertices_split += static_cast<uint32_t>(points.size() - points_before);
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    return absl::InternalError("repair: the triangles could not be made into a manifold mesh");
  }
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return mesh;
}

absl::StatusOr<TriangleMesh> repair(const TriangleMesh& input, const RepairParams& params,
                                    const RunContext& context, RepairCounts& counts) {
  counts = RepairCounts{};
  LABELMESH_ASSIGN_OR_RETURN(auto built, mesh_from_soup(input, counts));
  Mesh& mesh = built;
  counts.non_manifold_vertices_split +=
      static_cast<uint32_t>(PMP::duplicate_non_manifold_vertices(mesh));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  // Collinear triangles first: the needle and cap tests assume a real triangle.
  const size_t faces_before = mesh.number_of_faces();
  PMP::remove_degenerate_faces(mesh);
  mesh.collect_garbage();
  counts.degenerate_triangles_removed +=
      static_cast<uint32_t>(faces_before - mesh.number_of_faces());

  const SharpCounts sharp_before = count_sharp_triangles(mesh, params);
  counts.needles_before = sharp_before.needles;
  counts.caps_before = sharp_before.caps;
  if (sharp_before.needles + sharp_before.caps > 0) {
    PMP::experimental::remove_almost_degenerate_faces(
        mesh, std::cos(params.cap_angle_deg * std::numbers::pi / 180), params.needle_ratio,
        params.max_collapse_length_mm);
    mesh.collect_garbage();
  }
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  std::vector<Mesh::Halfedge_index> holes;
  PMP::extract_boundary_cycles(mesh, std::back_inserter(holes));
  for (auto h : holes) {
    std::vector<Mesh::Face_index> patch;
    PMP::triangulate_hole(mesh, h, std::back_inserter(patch));
    if (!patch.empty()) ++counts.holes_filled;
  }
  // Nothing collapsed or filled leaves the triangles as counted (on Marching
  // Cubes surfaces the usual case; a count is costly on large surfaces).
  const bool changed = sharp_before.needles + sharp_before.caps > 0 || !holes.empty();
  const SharpCounts sharp_after = changed ? count_sharp_triangles(mesh, params) : sharp_before;
  counts.needles_after = sharp_after.needles;
  counts.caps_after = sharp_after.caps;

  if (CGAL::is_closed(mesh)) {
    PMP::orient_to_bound_a_volume(mesh);
  } else {
    PMP::orient(mesh);
  }
  PMP::remove_isolated_vertices(mesh);
  mesh.collect_garbage();
  return cgal::from_surface_mesh(mesh);
}

}  // namespace

absl::StatusOr<TriangleMesh> repair_surface(const TriangleMesh& input, const RepairParams& params,
                                            const RunContext& context, RepairCounts& counts) {
  try {
    return repair(input, params, context, counts);
  } catch (...) {
    return current_exception_status("repair");
  }
}

}  // namespace labelmesh::surface
