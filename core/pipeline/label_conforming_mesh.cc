// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/label_conforming_mesh.h"

#include <map>

#include "core/conforming/conforming_mesher.h"
#include "core/pipeline/label_tet_meshes.h"
#include "core/surface/surface_statistics.h"
#include "core/util/stage_timer.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

// Each label's boundary faces as a closed surface with its own point list.
std::map<int32_t, surface::TriangleMesh> label_surfaces(const volume_mesh::TetMesh& mesh) {
  std::map<int32_t, surface::TriangleMesh> surfaces;
  std::map<int32_t, std::map<uint32_t, uint32_t>> point_of;
  for (const auto& face : volume_mesh::label_boundary_faces(mesh)) {
    auto& surface = surfaces[face.label];
    auto& points = point_of[face.label];
    std::array<uint32_t, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      const auto [it, added] =
          points.try_emplace(face.points[k], static_cast<uint32_t>(surface.points.size()));
      if (added) surface.points.push_back(mesh.points[face.points[k]]);
      triangle[k] = it->second;
    }
    surface.triangles.push_back(triangle);
  }
  return surfaces;
}

}  // namespace

absl::Status add_conforming_mesh(const volume::LabelVolume& volume,
                                 const std::vector<int32_t>& labels, const MeshParams& params,
                                 const RunContext& context, MeshResult& result) {
  conforming::ConformingParams conforming;
  conforming.max_interface_faces = params.conforming_max_interface_faces;
  conforming.tetgen = params.tetgen;
  // Points TetGen added on the interfaces would split the triangles the
  // labels share and the slides follow: the interfaces are always kept.
  conforming.tetgen.keep_boundary = true;
  conforming.improve = params.improve;
  conforming.improve.max_volume_mm3 = params.tetgen.max_volume_mm3;
  // Peeling would move the outer boundary away from the interfaces.
  conforming.improve.max_peel_depth_mm = 0;

  VolumeResult volume_result;
  volume_result.mesher = "conforming";
  conforming::ConformingFigures figures;
  volume_mesh::ImproveFigures improve;
  absl::StatusOr<volume_mesh::TetMesh> mesh;
  {
    StageTimer timer(result.stages, "conforming_mesh");
    context.report("conforming_mesh", 0);
    mesh = conforming::mesh_conforming(volume, labels, conforming, context, figures, improve);
  }
  if (!mesh.ok()) return mesh.status();
  volume_result.mesh = std::move(*mesh);
  volume_result.steiner_points = figures.tetgen.steiner_points;
  volume_result.seconds = figures.seconds;
  measure(volume_result);
  if (conforming.improve.target_quality > 0)
    volume_result.improvement = VolumeImprovement{figures.tetgen_quality, improve};

  StageTimer timer(result.stages, "surface_statistics");
  auto surfaces = label_surfaces(volume_result.mesh);
  for (const auto& label : figures.labels) {
    if (label.tetrahedra == 0) {
      result.warnings.push_back(
          {label.label, cat("no volume mesh: none of its ", label.voxels,
                            " voxels is inside the conforming mesh's tetrahedra")});
      continue;
    }
    SurfaceResult surface;
    surface.label = label.label;
    surface.stage = "conforming";
    surface.is_output = true;
    surface.mesh = std::move(surfaces[label.label]);
    surface.statistics = surface::compute_surface_statistics(surface.mesh);
    result.surfaces.push_back(std::move(surface));
  }
  volume_result.conforming = std::move(figures);
  result.volume = std::move(volume_result);
  return absl::OkStatus();
}

}  // namespace labelmesh
