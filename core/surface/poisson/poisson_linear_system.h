// SPDX-License-Identifier: AGPL-3.0-or-later
// The Poisson solve's linear system: the cancellable conjugate gradient that
// solves it, and how it is assembled. Included only by the Poisson
// translation unit and its test: CGAL's Poisson headers are slow to compile.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <numeric>
#include <utility>
#include <vector>

#include <CGAL/Eigen_sparse_matrix.h>
#include <CGAL/Eigen_vector.h>
#include <CGAL/Poisson_reconstruction_function.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>
#include <Eigen/IterativeLinearSolvers>

#include "core/surface/poisson/poisson_kernel.h"
#include "core/surface/poisson/time_stamped_bases.h"
#include "core/util/run_context.h"

namespace labelmesh::surface::poisson {

// Eigen's Jacobi preconditioner, which conjugate gradient applies once per
// iteration: the one hook inside the solve where a stop request can be seen.
class CancellablePreconditioner : public Eigen::DiagonalPreconditioner<double> {
 public:
  void set_context(const RunContext* context) { context_ = context; }

  template <typename Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    if (context_ != nullptr && context_->stop_requested()) throw Cancelled{};
    return Eigen::DiagonalPreconditioner<double>::solve(b);
  }

 private:
  const RunContext* context_ = nullptr;
};

// Conjugate gradient to a relative residual, cancellable at every iteration;
// a model of CGAL's SparseLinearAlgebraTraits_d.
class CancellableSolver {
 public:
  // The lower triangle of the symmetric matrix.
  using Matrix = CGAL::Eigen_sparse_symmetric_matrix<double>;
  using Vector = CGAL::Eigen_vector<double>;
  using NT = double;

  CancellableSolver(const RunContext* context, double tolerance, int* iterations)
      : context_(context), tolerance_(tolerance), iterations_(iterations) {}

  bool linear_solver(const Matrix& a, const Vector& b, Vector& x, NT& d) {
    d = 1;
    Eigen::ConjugateGradient<Matrix::EigenType, Eigen::Lower, CancellablePreconditioner> solver;
    solver.preconditioner().set_context(context_);
    solver.setTolerance(tolerance_);
    solver.compute(a.eigen_object());
    if (solver.info() != Eigen::Success) return false;
    x = solver.solve(b);
    *iterations_ += static_cast<int>(solver.iterations());
    return solver.info() == Eigen::Success;
  }

 private:
  const RunContext* context_;
  double tolerance_;
  int* iterations_;
};

// The triangulation's finite vertices but its constrained one, along a
// Hilbert curve through their points: numbered in this order, neighbours in
// space are neighbours in memory, for the assembly's walks and the solver's
// products alike.
template <class Triangulation>
std::vector<typename Triangulation::Vertex_handle> along_hilbert_curve(const Triangulation& tr) {
  std::vector<typename Triangulation::Vertex_handle> vertices;
  std::vector<CGAL::Epick::Point_3> points;
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v) {
    if (tr.is_constrained(v)) continue;
    vertices.push_back(v);
    points.emplace_back(v->point().x(), v->point().y(), v->point().z());
  }
  std::vector<std::size_t> order(vertices.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  using Traits =
      CGAL::Spatial_sort_traits_adapter_3<CGAL::Epick,
                                          CGAL::Pointer_property_map<CGAL::Epick::Point_3>::type>;
  CGAL::hilbert_sort(order.begin(), order.end(), Traits(CGAL::make_property_map(points)));
  std::vector<typename Triangulation::Vertex_handle> sorted;
  sorted.reserve(order.size());
  for (std::size_t i : order) sorted.push_back(vertices[i]);
  return sorted;
}

}  // namespace labelmesh::surface::poisson

// The solve's triangulation must take the time-stamped bases, or its orders
// follow heap addresses again.
static_assert(CGAL::internal::Has_timestamp<CGAL::Poisson_reconstruction_function<
                      labelmesh::surface::poisson::StopAwareKernel>::Triangulation::Cell>::value &&
                  CGAL::internal::Has_timestamp<CGAL::Poisson_reconstruction_function<
                      labelmesh::surface::poisson::StopAwareKernel>::Triangulation::Vertex>::value,
              "the Poisson triangulation lost its creation stamps");

// CGAL's solve_poisson for this solver: CGAL's linear system (cotangent
// weights as Voronoi face area over edge length; on the right the
// divergence of the points' normals, in CGAL's default unnormalised form;
// lambda added to the input points' diagonal), assembled faster and in less
// memory. CGAL's own version walks each vertex's cells twice (once for the
// divergence, once to list its edges) and weighs each edge twice, once from
// each end, allocating as it goes. Here one walk per vertex serves both, and
// each edge is weighed once, which also makes the matrix exactly symmetric.
// Where CGAL's weights are well defined its entries and this one's differ by
// rounding only (on the liver, 2e-14 of the largest); see the face area
// below for where they are not. On the liver this takes about a fifth off
// the assembly.
//
// The unknowns are numbered along a Hilbert curve, and the cells (with their
// circumcentres) in the order the walk first meets them, where CGAL numbers
// both in memory order, which scatters neighbours after the solve's batches
// of insertion and refinement. On the liver this takes about a third off the
// assembly and up to a fifth off the conjugate gradient.
//
// CGAL also fills a cache of barycentric coordinates here, 80 bytes a cell
// (100 MiB a half on the liver), for its own operator() and special_func.
// The pipeline evaluates the function with HintedEvaluator instead, so the
// cache is left empty: CGAL's evaluators must not be called on a function
// solved with this solver.
//
// Polls for a stop once a vertex, through poll_for_stop.
template <>
template <>
inline bool CGAL::Poisson_reconstruction_function<labelmesh::surface::poisson::StopAwareKernel>::
    solve_poisson<labelmesh::surface::poisson::CancellableSolver>(
        labelmesh::surface::poisson::CancellableSolver solver, double lambda) {
  using Solver = labelmesh::surface::poisson::CancellableSolver;
  constrain_one_vertex_on_convex_hull();
  const std::vector<Vertex_handle> unknown =
      labelmesh::surface::poisson::along_hilbert_curve(*m_tr);
  for (std::size_t i = 0; i < unknown.size(); ++i)
    unknown[i]->index() = static_cast<unsigned int>(i);
  const auto unknowns = static_cast<unsigned int>(unknown.size());
  Solver::Matrix a(unknowns);
  Solver::Vector x(unknowns), b(unknowns);
  // Cells are numbered, and their circumcentres computed, as the walk below
  // first meets them.
  for (auto cell = m_tr->all_cells_begin(); cell != m_tr->all_cells_end(); ++cell)
    cell->info() = -1;
  Dual.clear();
  Dual.reserve(m_tr->number_of_cells());

  std::vector<double> diagonal(unknowns, 0.0);
  std::vector<Cell_handle> cells;
  // Each neighbour this vertex weighs the edge to, with a cell of that edge.
  std::vector<std::pair<Vertex_handle, Cell_handle>> neighbours;
  std::vector<Point> face;
  for (std::size_t row = 0; row < unknown.size(); ++row) {
    const Vertex_handle v = unknown[row];
    labelmesh::surface::poisson::poll_for_stop();
    cells.clear();
    m_tr->incident_cells(v, std::back_inserter(cells));

    // Divergence (CGAL's default, unnormalised form): through the face
    // opposite v of each finite cell, that face's area vector against the
    // sum of its corners' normals.
    FT divergence = 0;
    for (Cell_handle cell : cells) {
      if (m_tr->is_infinite(cell)) continue;
      if (cell->info() < 0) {
        cell->info() = static_cast<int>(Dual.size());
        Dual.push_back(m_tr->dual(cell));
      }
      const int at = cell->index(v);
      const Vertex_handle q0 = cell->vertex(m_tr->vertex_triple_index(at, 0));
      const Vertex_handle q1 = cell->vertex(m_tr->vertex_triple_index(at, 1));
      const Vertex_handle q2 = cell->vertex(m_tr->vertex_triple_index(at, 2));
      const Vector area = CGAL::cross_product(q1->point() - q0->point(), q2->point() - q0->point());
      divergence += area * (q0->normal() + q1->normal() + q2->normal());
    }
    b[row] = divergence;

    neighbours.clear();
    for (Cell_handle cell : cells) {
      for (int k = 0; k < 4; ++k) {
        const Vertex_handle w = cell->vertex(k);
        if (w == v || m_tr->is_infinite(w)) continue;
        // An edge to an earlier unknown was weighed from that end.
        if (!m_tr->is_constrained(w) && static_cast<std::size_t>(w->index()) < row) continue;
        const bool seen = std::any_of(neighbours.begin(), neighbours.end(),
                                      [w](const auto& n) { return n.first == w; });
        if (!seen) neighbours.emplace_back(w, cell);
      }
    }
    for (const auto& [w, cell] : neighbours) {
      Edge edge(cell, cell->index(v), cell->index(w));
      const Vector along = w->point() - v->point();
      const FT squared_length = along * along;
      // The Voronoi face dual to the edge: the circumcentres of the cells
      // around it, in order, a planar polygon across the edge.
      face.clear();
      bool bounded = true;
      Cell_circulator around = m_tr->incident_cells(edge), start = around;
      do {
        const Cell_handle around_cell = around;
        if (m_tr->is_infinite(around_cell)) {
          bounded = false;
          break;
        }
        face.push_back(Dual[around_cell->info()]);
      } while (++around != start);
      FT weight = 0;
      if (!bounded) {
        weight = area_voronoi_face_boundary(edge) / std::sqrt(squared_length);
      } else {
        // Its signed area along the edge. CGAL adds unsigned triangles of a
        // fan instead, which is the same for a convex polygon but, where
        // cocircular points leave a flat cell whose circumcentre sticks out
        // of the polygon (a parametric torus, say), depends on the cell the
        // fan starts from: the same edge got 3.5 from one end and 2.1 from
        // the other. The signed area cancels such a spike.
        Vector twice_area = CGAL::NULL_VECTOR;
        for (std::size_t i = 1; i + 1 < face.size(); ++i)
          twice_area = twice_area + CGAL::cross_product(face[i] - face[0], face[i + 1] - face[0]);
        weight = std::abs(twice_area * along) / (2 * squared_length);
      }
      diagonal[row] += weight;
      if (m_tr->is_constrained(w)) {
        b[row] -= weight * w->f();
      } else {
        const auto column = static_cast<std::size_t>(w->index());
        diagonal[column] += weight;
        a.set_coef(column, row, -weight, true);
      }
    }
  }
  for (std::size_t row = 0; row < unknown.size(); ++row) {
    const double screen = unknown[row]->type() == Triangulation::INPUT ? lambda : 0.0;
    a.set_coef(row, row, diagonal[row] + screen, true);
  }
  // Released, not just cleared as by CGAL's clear_duals(): 24 bytes a cell
  // that would otherwise stay allocated through meshing.
  std::vector<Point>().swap(Dual);

  double denominator = 1;
  if (!solver.linear_solver(a, b, x, denominator)) return false;
  for (std::size_t row = 0; row < unknown.size(); ++row) unknown[row]->f() = x[row];
  return true;
}
