// SPDX-License-Identifier: AGPL-3.0-or-later
// The kernel CGAL's Poisson reconstruction is instantiated with, and how a
// stop request reaches code of CGAL's that offers no callback. Included only
// by the Poisson translation unit and its tests: CGAL's Poisson headers are
// slow to compile.
#pragma once

#include <cstdint>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/version.h>

#include "core/util/run_context.h"

// The Poisson adapters reach into CGAL 5.5's Poisson_reconstruction_function:
// they evaluate its function with their own cell hints and assemble and solve
// its linear system themselves. Another CGAL version has to be checked against
// them before it is built.
static_assert(CGAL_VERSION_NR >= 1050500000 && CGAL_VERSION_NR < 1050600000,
              "the Poisson adapters follow CGAL 5.5's Poisson_reconstruction_function");

namespace labelmesh::surface::poisson {

// Thrown from inside CGAL's loops when a stop is requested.
struct Cancelled {};

// The run whose Poisson solve this thread is doing, while a SolveScope lives.
inline thread_local const RunContext* solving_run = nullptr;

// Marks this thread as solving for `run` until the scope ends.
class SolveScope {
 public:
  explicit SolveScope(const RunContext& run) { solving_run = &run; }
  ~SolveScope() { solving_run = nullptr; }
  SolveScope(const SolveScope&) = delete;
  SolveScope& operator=(const SolveScope&) = delete;
};

// Throws Cancelled on one call in 4,096 if this thread's run was asked to
// stop: the polls cost nothing measurable, and 4,096 calls pass quickly
// enough that a stop still takes effect at once.
inline void poll_for_stop() {
  static thread_local uint32_t calls = 0;
  if ((++calls & 4095) == 0 && solving_run != nullptr && solving_run->stop_requested())
    throw Cancelled{};
}

// Epick, whose squared-distance functor also polls for a stop. CGAL's
// Delaunay refinement inside the Poisson solve has no callback, but it tests
// every new cell's edge lengths with this functor, so a stop ends the
// refinement at once instead of after it (a noticeable delay on large
// surfaces). The points and every other type and functor are Epick's own.
struct StopAwareKernel : CGAL::Epick {
  struct Compute_squared_distance_3 : CGAL::Epick::Compute_squared_distance_3 {
    template <typename... Args>
    auto operator()(const Args&... args) const {
      poll_for_stop();
      return CGAL::Epick::Compute_squared_distance_3::operator()(args...);
    }
  };
  Compute_squared_distance_3 compute_squared_distance_3_object() const { return {}; }
};

}  // namespace labelmesh::surface::poisson
