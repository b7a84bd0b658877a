// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/smooth_surface.h"

#include <cmath>

#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include "core/surface/write_surface.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::surface {

absl::StatusOr<TriangleMesh> smooth_surface(const TriangleMesh& mesh, const SmoothingParams& params,
                                            const RunContext& context) {
  if (params.iterations < 0 || params.iterations > 200)
    return absl::InvalidArgumentError(
        cat("smoothing-iterations: ", params.iterations, " is outside 0..200"));
  if (!(params.pass_band > 0 && params.pass_band < 2))
    return absl::InvalidArgumentError(
        cat("smoothing-pass-band: ", params.pass_band, " is outside (0, 2)"));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  if (params.iterations == 0 || mesh.triangles.empty()) return mesh;

  vtkNew<vtkWindowedSincPolyDataFilter> filter;
  filter->SetInputData(to_polydata(mesh));
  filter->SetNumberOfIterations(params.iterations);
  filter->SetPassBand(params.pass_band);
  // Every vertex is smoothed alike: Marching Cubes has no true creases, and
  // its staircase edges would otherwise be kept as features.
  filter->FeatureEdgeSmoothingOff();
  filter->BoundarySmoothingOn();
  filter->NonManifoldSmoothingOn();
  // Scaling into a unit cube keeps the Chebyshev recursion well conditioned.
  filter->NormalizeCoordinatesOn();
  filter->Update();
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  vtkPoints* moved = filter->GetOutput()->GetPoints();
  if (moved == nullptr || moved->GetNumberOfPoints() != vtkIdType(mesh.points.size()))
    return absl::InternalError("smoothing: VTK's filter changed the number of points");
  TriangleMesh result = mesh;
  for (size_t i = 0; i < result.points.size(); ++i) {
    moved->GetPoint(vtkIdType(i), result.points[i].data());
    for (double c : result.points[i]) {
      if (!std::isfinite(c)) return absl::InternalError("smoothing: a point became non-finite");
    }
  }
  return result;
}

}  // namespace labelmesh::surface
