// SPDX-License-Identifier: AGPL-3.0-or-later
// The restricted Delaunay triangulation CGAL's surface mesher builds, and
// the closed surface read out of it. Included only by the CGAL translation
// units that mesh surfaces (Poisson, level sets): the headers are slow to
// compile.
#pragma once

#include <algorithm>
#include <array>
#include <unordered_map>
#include <vector>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_with_circumcenter_3.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Robust_circumcenter_traits_3.h>
#include <CGAL/Surface_mesh_cell_base_3.h>
#include <CGAL/Surface_mesh_complex_2_in_triangulation_3.h>
#include <CGAL/Surface_mesh_vertex_base_3.h>
#include <CGAL/boost/graph/helpers.h>

#include "absl/status/statusor.h"
#include "core/surface/cgal/cgal_mesh.h"

namespace labelmesh::surface::restricted_delaunay {

using cgal::Kernel;
using cgal::Point;

// Adds CGAL's creation-order time stamp to a vertex or cell base. CGAL then
// orders and hashes handles by that stamp instead of by address, so the
// surface mesher's sets of bad vertices and edges are walked in the same order
// in every process (the default triangulation gave the liver 15,798 nodes in
// the CLI and 15,890 in the server's worker).
template <class Base>
class TimeStamped : public Base {
 public:
  using Has_timestamp = CGAL::Tag_true;
  template <class Tds>
  struct Rebind_TDS {
    using Other = TimeStamped<typename Base::template Rebind_TDS<Tds>::Other>;
  };
  using Base::Base;

  std::size_t time_stamp() const { return time_stamp_; }
  void set_time_stamp(std::size_t stamp) { time_stamp_ = stamp; }

 private:
  std::size_t time_stamp_ = std::size_t(-1);
};

// CGAL's Surface_mesh_default_triangulation_3 with time-stamped bases.
using MesherTraits = CGAL::Robust_circumcenter_traits_3<Kernel>;
using MesherVertexBase = TimeStamped<CGAL::Surface_mesh_vertex_base_3<MesherTraits>>;
using MesherCellBase = TimeStamped<CGAL::Delaunay_triangulation_cell_base_with_circumcenter_3<
    MesherTraits, CGAL::Surface_mesh_cell_base_3<MesherTraits>>>;
using Triangulation = CGAL::Delaunay_triangulation_3<
    MesherTraits, CGAL::Triangulation_data_structure_3<MesherVertexBase, MesherCellBase>>;
using Complex = CGAL::Surface_mesh_complex_2_in_triangulation_3<Triangulation>;
using OutputMesh = cgal::Mesh;

// The triangles of the restricted Delaunay surface, in the triangulation's
// own (deterministic) vertex order, oriented outward by CGAL (which handles
// nested components), and sorted so the order never depends on addresses.
inline absl::StatusOr<TriangleMesh> complex_to_mesh(const Complex& complex,
                                                    const Triangulation& tr) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<std::array<Triangulation::Vertex_handle, 3>> facets;
  for (auto f = tr.finite_facets_begin(); f != tr.finite_facets_end(); ++f) {
    if (!complex.is_in_complex(*f)) continue;
    const auto cell = f->first;
    const int i = f->second;
    facets.push_back({cell->vertex(tr.vertex_triple_index(i, 0)),
                      cell->vertex(tr.vertex_triple_index(i, 1)),
                      cell->vertex(tr.vertex_triple_index(i, 2))});
  }
  std::unordered_map<Triangulation::Vertex_handle, size_t> index;
  for (const auto& facet : facets) {
    for (auto v : facet) index.emplace(v, 0);
  }
  std::vector<Point> points;
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v) {
    auto found = index.find(v);
    if (found == index.end()) continue;
    found->second = points.size();
    points.push_back(v->point());
  }
  std::vector<std::array<size_t, 3>> triangles;
  triangles.reserve(facets.size());
  for (const auto& f : facets) triangles.push_back({index[f[0]], index[f[1]], index[f[2]]});
  // CGAL duplicates a point only where the soup is not a manifold: with
  // none duplicated it is a polygon mesh, and the second look at every
  // polygon (noticeable on large surfaces) is only needed when some were.
  const bool manifold = PMP::orient_polygon_soup(points, triangles);
  if (!manifold && !PMP::is_polygon_soup_a_polygon_mesh(triangles))
    return absl::InternalError("the meshed surface is not a manifold");
  OutputMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, triangles, mesh);
  // Orienting needs a closed surface; an open one would be read past its
  // border.
  if (!CGAL::is_closed(mesh)) return absl::InternalError("the meshed surface is not closed");
  PMP::orient_to_bound_a_volume(mesh);
  TriangleMesh result = cgal::from_surface_mesh(mesh);
  for (auto& t : result.triangles)
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(result.triangles.begin(), result.triangles.end());
  return result;
}

}  // namespace labelmesh::surface::restricted_delaunay
