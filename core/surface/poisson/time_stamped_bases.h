// SPDX-License-Identifier: AGPL-3.0-or-later
// Creation-order time stamps for the vertices and cells of the triangulation
// inside CGAL's Poisson solve, so that every order CGAL takes from handles
// is the order in which they were made, not where the heap put them.
//
// CGAL compares and hashes handles of elements without a time stamp by
// address. The Delaunay refinement inside the solve queues cells of equal
// quality (common on voxel data) by that order, so the same input gave a
// different surface in about one process in twenty. Poisson_reconstruction_
// function fixes its triangulation type, so the stamps are added by
// specialising two of its bases for the Poisson kernel alone; no other
// triangulation in the project is touched.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <CGAL/Reconstruction_triangulation_3.h>
#include <CGAL/Robust_weighted_circumcenter_filtered_traits_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_3.h>

#include "core/surface/poisson/poisson_kernel.h"

namespace labelmesh::surface::poisson {

// The geometric traits of Poisson_reconstruction_function<StopAwareKernel>'s
// triangulation, as CGAL 5.5 builds them.
using PoissonTriangulationTraits = CGAL::Reconstruction_triangulation_default_geom_traits_3<
    CGAL::Robust_circumcenter_filtered_traits_3<StopAwareKernel>>;

// The stamp an element carries; CGAL's Compact_container assigns it at
// insertion when it is still unset. 32 bits fit where the elements had
// padding, so the triangulation takes no more memory; a solve that made more
// than four billion cells would need over a terabyte first.
class CreationStamp {
 public:
  using Has_timestamp = std::true_type;
  std::size_t time_stamp() const {
    return stamp_ == kUnset ? static_cast<std::size_t>(-1) : stamp_;
  }
  void set_time_stamp(std::size_t stamp) {
    if (stamp != static_cast<std::size_t>(-1) && stamp >= kUnset)
      throw std::length_error("the Poisson triangulation made over 2^32 elements");
    stamp_ = static_cast<std::uint32_t>(stamp);
  }

 private:
  static constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t stamp_ = kUnset;
};

}  // namespace labelmesh::surface::poisson

namespace CGAL {

// The Poisson triangulation's vertex point storage (the
// TriangulationVertexBase_3 concept), with a creation stamp.
template <class DSVb>
class Triangulation_vertex_base_3<labelmesh::surface::poisson::PoissonTriangulationTraits, DSVb>
    : public DSVb, public labelmesh::surface::poisson::CreationStamp {
 public:
  using Geom_traits = labelmesh::surface::poisson::PoissonTriangulationTraits;
  using Cell_handle = typename DSVb::Cell_handle;
  using Point = typename Geom_traits::Point_3;
  using Has_timestamp = std::true_type;

  template <typename TDS2>
  struct Rebind_TDS {
    using Other =
        Triangulation_vertex_base_3<Geom_traits, typename DSVb::template Rebind_TDS<TDS2>::Other>;
  };

  Triangulation_vertex_base_3() = default;
  explicit Triangulation_vertex_base_3(const Point& p) : point_(p) {}
  Triangulation_vertex_base_3(const Point& p, Cell_handle c) : DSVb(c), point_(p) {}
  explicit Triangulation_vertex_base_3(Cell_handle c) : DSVb(c) {}

  const Point& point() const { return point_; }
  Point& point() { return point_; }
  void set_point(const Point& p) { point_ = p; }

 private:
  Point point_;
};

// The Poisson triangulation's cell with its int info, with a creation stamp.
template <class Cb>
class Triangulation_cell_base_with_info_3<
    int, labelmesh::surface::poisson::PoissonTriangulationTraits, Cb>
    : public Cb, public labelmesh::surface::poisson::CreationStamp {
 public:
  using Vertex_handle = typename Cb::Vertex_handle;
  using Cell_handle = typename Cb::Cell_handle;
  using Info = int;
  using Has_timestamp = std::true_type;

  template <typename TDS2>
  struct Rebind_TDS {
    using Other =
        Triangulation_cell_base_with_info_3<int,
                                            labelmesh::surface::poisson::PoissonTriangulationTraits,
                                            typename Cb::template Rebind_TDS<TDS2>::Other>;
  };

  Triangulation_cell_base_with_info_3() = default;
  Triangulation_cell_base_with_info_3(Vertex_handle v0, Vertex_handle v1, Vertex_handle v2,
                                      Vertex_handle v3)
      : Cb(v0, v1, v2, v3) {}
  Triangulation_cell_base_with_info_3(Vertex_handle v0, Vertex_handle v1, Vertex_handle v2,
                                      Vertex_handle v3, Cell_handle n0, Cell_handle n1,
                                      Cell_handle n2, Cell_handle n3)
      : Cb(v0, v1, v2, v3, n0, n1, n2, n3) {}

  const Info& info() const { return info_; }
  Info& info() { return info_; }

 private:
  Info info_{};
};

}  // namespace CGAL
