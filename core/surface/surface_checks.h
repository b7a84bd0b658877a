// SPDX-License-Identifier: AGPL-3.0-or-later
// Geometric checks of a finished surface with CGAL: self-intersections and
// the distance to another surface (how far a reconstruction strays from the
// Marching Cubes surface it came from).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "core/surface/triangle_mesh.h"
#include "core/util/run_context.h"

namespace labelmesh::surface {

// Pairs of triangles that intersect other than along a shared edge or
// vertex. nullopt when `mesh` is not a valid polygon mesh (CGAL needs one).
std::optional<uint64_t> count_self_intersections(const TriangleMesh& mesh);

struct SurfaceDistance {
  // Largest distance from a sample on either surface to the other surface.
  double hausdorff_mm = 0;
  // Mean over the samples of both surfaces.
  double mean_mm = 0;
  // The sample where the Hausdorff distance is reached (LPS, mm): where to
  // look when a reconstruction strays.
  std::array<double, 3> hausdorff_at{0, 0, 0};
};

// One surface's side of surface_distance: its samples and a search tree over
// its triangles. Building it for a large Marching Cubes surface is costly
// enough that the pipeline builds it beside other work.
class DistanceReference {
 public:
  // Built in steps of similar cost: a stop request between them leaves it
  // empty, measuring nothing.
  DistanceReference(const TriangleMesh& mesh, double sample_spacing_mm,
                    const RunContext& context = {});
  ~DistanceReference();
  DistanceReference(const DistanceReference&) = delete;
  DistanceReference& operator=(const DistanceReference&) = delete;

  double sample_spacing_mm() const { return sample_spacing_mm_; }

 private:
  friend class DistanceMeasurement;
  struct Parts;
  const Parts& parts() const { return *parts_; }
  std::unique_ptr<Parts> parts_;
  double sample_spacing_mm_;
};

// Symmetric distance between `a` and `b`, sampled at every vertex, along
// every edge longer than `sample_spacing_mm` and inside every triangle, no
// more than about that far apart (deterministic; uses two threads). The
// Hausdorff figure is a lower bound, within half the spacing of the true one
// (distance to a surface changes no faster than the sample moves). The
// queries stop early when `context` asks to: the figures are then partial,
// and the caller checks for the stop before using them.
SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleMesh& b,
                                 double sample_spacing_mm, const RunContext& context = {});

// The same, with `b` prepared beforehand (at its own sample spacing).
SurfaceDistance surface_distance(const TriangleMesh& a, const DistanceReference& b,
                                 const RunContext& context = {});

// surface_distance as work that threads can share: each work() call measures
// chunks of samples until none are left, so a thread done with other work
// (TetGen, say) can join one already measuring. The figures do not depend on
// which thread measured which chunk. `a` and `b` must outlive it.
class DistanceMeasurement {
 public:
  DistanceMeasurement(const TriangleMesh& a, const DistanceReference& b);
  ~DistanceMeasurement();
  DistanceMeasurement(const DistanceMeasurement&) = delete;
  DistanceMeasurement& operator=(const DistanceMeasurement&) = delete;

  // Safe to call from several threads at once. Returns early on a stop
  // request (the figures are then partial).
  void work(const RunContext& context);
  // Once every work() call has returned.
  SurfaceDistance result() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace labelmesh::surface
