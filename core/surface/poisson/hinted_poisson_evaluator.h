// SPDX-License-Identifier: AGPL-3.0-or-later
// The solved Poisson function evaluated for the surface mesher. Included only
// by the Poisson translation unit and its test: CGAL's Poisson headers are slow
// to compile.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <CGAL/Poisson_reconstruction_function.h>
#include <boost/tuple/tuple.hpp>

#include "core/surface/cgal/cgal_mesh.h"
#include "core/surface/poisson/poisson_kernel.h"
#include "core/surface/poisson/time_stamped_bases.h"
#include "core/util/run_context.h"

namespace labelmesh::surface::poisson {

using cgal::Kernel;
using cgal::Point;
using Vector = Kernel::Vector_3;
using PoissonFunction = CGAL::Poisson_reconstruction_function<StopAwareKernel>;

// Evaluates the solved implicit function for the surface mesher. Each value
// means locating the point in the solve's triangulation, and CGAL walks there
// from its previous answer; the mesher's queries jump across the surface, so
// on the liver 3.3 M such walks took about three quarters of the meshing
// time. Here a long jump starts from the cell first found in the query's
// cube of a grid of about two million cubes (or, the first time there, of a
// grid four times coarser), a short one from the last answer, and the
// oracle's second question about a segment's ends (it asks for their sign,
// then for their value and cell) is answered from the last four answers.
// Every answer depends only on the order of the queries, so meshing stays
// deterministic. Polls for a stop every few thousand evaluations.
class HintedEvaluator {
 public:
  using FT = Kernel::FT;
  using Triangulation = PoissonFunction::Triangulation;
  using Cell_handle = PoissonFunction::Cell_handle;
  // The value at a point, the cell that holds it, and whether that cell is
  // outside the convex hull: what CGAL's special_func answers.
  using Answer = boost::tuple<FT, Cell_handle, bool>;

  HintedEvaluator(const PoissonFunction& function, const RunContext& context)
      : tr_(function.tr()), context_(context) {
    const CGAL::Bbox_3 box = CGAL::bbox_3(tr_.points_begin(), tr_.points_end());
    const double volume =
        (box.xmax() - box.xmin()) * (box.ymax() - box.ymin()) * (box.zmax() - box.zmin());
    const double longest =
        std::max({box.xmax() - box.xmin(), box.ymax() - box.ymin(), box.zmax() - box.zmin(), 1e-9});
    // About two million cubes (16 MB): a few cells across each on the liver.
    // The second bound keeps a flat or empty box from asking for more.
    const double step = std::max(std::cbrt(volume / double(1 << 21)), longest / 1024);
    // A triangulation that is not yet a volume gets no grid (and no walks
    // from it); the solve never leaves one, but the box would be infinite.
    const bool volume_ok = tr_.dimension() == 3;
    fine_ = Grid(box, step, volume_ok);
    // The first question in a cube of the fine grid starts from the coarse
    // one's cell, 4 cubes across: the last answer may be across the organ
    // (on the liver, those walks were a third of the locating time).
    coarse_ = Grid(box, 4 * step, volume_ok);
    last_ = tr_.infinite_cell();
    // Epick points start uninitialised; NaN matches no query.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (auto& entry : recent_) entry.first = Point(nan, nan, nan);
  }

  Answer evaluate(const Point& p) {
    for (const auto& [point, answer] : recent_) {
      if (point == p) return answer;
    }
    if ((++calls_ & 4095) == 0 && context_.stop_requested()) throw Cancelled{};
    // The oracle's search along a segment asks next door to its last
    // question: walk from there.
    Cell_handle* slot = fine_.slot_for(p);
    Cell_handle* coarse_slot = coarse_.slot_for(p);
    Cell_handle start = last_;
    if (CGAL::squared_distance(p, last_point_) >= fine_.step * fine_.step) {
      if (slot != nullptr && *slot != Cell_handle()) {
        start = *slot;
      } else if (coarse_slot != nullptr && *coarse_slot != Cell_handle()) {
        start = *coarse_slot;
      }
    }
    const Cell_handle cell = tr_.locate(p, start);
    if (slot != nullptr && *slot == Cell_handle()) *slot = cell;
    if (coarse_slot != nullptr && *coarse_slot == Cell_handle()) *coarse_slot = cell;
    last_ = cell;
    last_point_ = p;
    const Answer answer = value_in(cell, p);
    recent_[next_recent_] = {p, answer};
    next_recent_ = (next_recent_ + 1) % recent_.size();
    return answer;
  }

 private:
  // Cubes over the triangulation's box, each holding the cell first found
  // in it.
  struct Grid {
    Grid() = default;
    Grid(const CGAL::Bbox_3& box, double cube, bool sized) : step(cube) {
      origin = {box.xmin(), box.ymin(), box.zmin()};
      if (sized) {
        for (int axis = 0; axis < 3; ++axis)
          size[axis] = int((box.max(axis) - box.min(axis)) / step) + 1;
      }
      slots.assign(size_t(size[0]) * size[1] * size[2], Cell_handle());
    }

    Cell_handle* slot_for(const Point& p) {
      size_t index = 0;
      for (int axis = 2; axis >= 0; --axis) {
        const double at = (p[axis] - origin[axis]) / step;
        if (!(at >= 0 && at < size[axis])) return nullptr;
        index = index * size[axis] + size_t(at);
      }
      return &slots[index];
    }

    double step = 1;
    std::array<double, 3> origin{};
    std::array<int, 3> size{};
    std::vector<Cell_handle> slots;
  };

  // Linear interpolation of the vertex values, as CGAL's own operator();
  // outside the convex hull, the value of a hull vertex.
  Answer value_in(Cell_handle cell, const Point& p) const {
    if (tr_.is_infinite(cell)) {
      const int i = cell->index(tr_.infinite_vertex());
      return {cell->vertex((i + 1) & 3)->f(), cell, true};
    }
    const auto weights = barycentric(cell, p);
    double value = 0;
    for (int i = 0; i < 4; ++i) value += weights[i] * cell->vertex(i)->f();
    return {value, cell, false};
  }

  // `p`'s barycentric coordinates in a finite `cell` (negative outside it).
  static std::array<double, 4> barycentric(Cell_handle cell, const Point& p) {
    const Point& d = cell->vertex(3)->point();
    const Vector da = cell->vertex(0)->point() - d, db = cell->vertex(1)->point() - d,
                 dc = cell->vertex(2)->point() - d, dp = p - d;
    const double whole = CGAL::determinant(da, db, dc);
    const double a = CGAL::determinant(dp, db, dc) / whole;
    const double b = CGAL::determinant(da, dp, dc) / whole;
    const double c = CGAL::determinant(da, db, dp) / whole;
    return {a, b, c, 1 - a - b - c};
  }

 public:
  // How many questions needed a located point so far.
  uint64_t located() const { return calls_; }

  // The point of segment [p1, p2] where the linear function of the finite
  // `cell`, minus `offset`, is zero, if that point lies in the cell (where
  // the function is that linear function): the exact crossing of the
  // piecewise linear function there, found from one located cell.
  std::optional<Point> zero_in_cell(Cell_handle cell, double offset, const Point& p1,
                                    const Point& p2) const {
    if (tr_.is_infinite(cell)) return std::nullopt;
    const double g1 = boost::get<0>(value_in(cell, p1)) - offset;
    const double g2 = boost::get<0>(value_in(cell, p2)) - offset;
    if (!(g1 != g2)) return std::nullopt;
    const double s = g1 / (g1 - g2);
    if (!(s >= 0 && s <= 1)) return std::nullopt;
    const Point zero = p1 + s * (p2 - p1);
    // A zero on a face of the cell is the neighbour's zero too.
    constexpr double kOnFace = -1e-12;
    for (double weight : barycentric(cell, zero)) {
      if (!(weight >= kOnFace)) return std::nullopt;
    }
    return zero;
  }

 private:
  const Triangulation& tr_;
  const RunContext& context_;
  Grid fine_, coarse_;
  Cell_handle last_;
  Point last_point_ = Point(CGAL::ORIGIN);
  std::array<std::pair<Point, Answer>, 4> recent_{};
  size_t next_recent_ = 0;
  // Questions answered by locating the point (not from the last answers).
  uint64_t calls_ = 0;
};

}  // namespace labelmesh::surface::poisson
