// Delaunay remeshing of a closed triangle surface: CGAL's surface mesher run
// on the surface itself (its inside as the implicit function), so the result
// has the same angle and size guarantees as a Poisson surface while staying
// within the distance bound of the input. The fallback for labels whose
// Poisson surface strays from the voxels.
#pragma once

#include "absl/status/statusor.h"
#include "core/run_context.h"
#include "core/surface/triangle_mesh.h"

namespace labelmesh::surface {

struct RemeshParams {
  // Smallest triangle angle, degrees, in (0, 30].
  double min_angle_deg = 30;
  // Longest triangle edge, mm.
  double max_edge_mm = 0;
  // Largest distance between a triangle's circumcentre and the input surface
  // where the triangle's dual Voronoi edge crosses it, mm.
  double max_distance_mm = 0;
};

// The remeshed surface: closed, 2-manifold, outward; the same input always
// gives the same mesh. `surface` must be closed and oriented (each component
// bounds a volume, nested ones allowed). Errors: INVALID_ARGUMENT for bad
// parameters or a surface that is not closed, FAILED_PRECONDITION for a
// surface of more than 60,000 points, INTERNAL when the mesher's result is not
// a manifold or it does not settle within a bounded number of inside tests,
// CANCELLED.
absl::StatusOr<TriangleMesh> remesh_surface(const TriangleMesh& surface, const RemeshParams& params,
                                            const RunContext& context);

}  // namespace labelmesh::surface
