// SPDX-License-Identifier: AGPL-3.0-or-later
// How far separate label surfaces enter each other: the nodes of each
// surface lying deeper than a given depth inside another (closed, outward)
// one. Touching labels that share one interface have none; per-label
// surfaces smoothed on their own overlap where their labels touch.
#pragma once

#include <vtkImplicitPolyDataDistance.h>
#include <vtkOBBTree.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/surface/triangle_mesh.h"
#include "core/surface/write_surface.h"
#include "core/volume/label_volume.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::testing {

struct LabelOverlap {
  size_t nodes = 0;            // nodes of every surface
  size_t inside = 0;           // of those, deeper than the depth inside another surface
  size_t labels_entering = 0;  // surfaces with at least one such node
};

// Counts, over `surfaces` (of `labels`, one each, in `volume`'s space), the
// nodes more than `depth_mm` inside another of them. A node is measured only
// against the surfaces of labels with a voxel within `reach_voxels` of it
// along each axis (a smoothed surface stays near its voxels): inside when its
// signed distance (its sign from the point normals interpolated at the
// nearest point) is below -depth_mm and a ray from it crosses the surface an
// odd number of times.
inline LabelOverlap nodes_inside_others(const std::vector<const surface::TriangleMesh*>& surfaces,
                                        const std::vector<int32_t>& labels,
                                        const volume::LabelVolume& volume, double depth_mm,
                                        int reach_voxels = 3) {
  const auto& g = volume.geometry;
  std::vector<int32_t> voxels(static_cast<size_t>(g.voxel_count()), 0);
  volume::visit_voxels(volume.voxels, [&](const auto* v, size_t count) {
    for (size_t i = 0; i < std::min(count, voxels.size()); ++i)
      voxels[i] = static_cast<int32_t>(v[i]);
  });
  // candidates[b][a]: the nodes of surface a near a voxel of labels[b].
  const size_t n = surfaces.size();
  std::vector<std::vector<std::vector<uint32_t>>> candidates(n,
                                                             std::vector<std::vector<uint32_t>>(n));
  std::vector<int32_t> near;
  for (size_t a = 0; a < n; ++a) {
    const auto& points = surfaces[a]->points;
    for (size_t i = 0; i < points.size(); ++i) {
      const auto index = g.to_index(points[i]);
      std::array<int64_t, 3> lo{}, hi{};
      for (int k = 0; k < 3; ++k) {
        const auto c = static_cast<int64_t>(std::llround(index[k]));
        lo[k] = std::max<int64_t>(0, c - reach_voxels);
        hi[k] = std::min<int64_t>(g.dims[k] - 1, c + reach_voxels);
      }
      near.clear();
      for (int64_t z = lo[2]; z <= hi[2]; ++z)
        for (int64_t y = lo[1]; y <= hi[1]; ++y)
          for (int64_t x = lo[0]; x <= hi[0]; ++x) {
            const int32_t l = voxels[static_cast<size_t>((z * g.dims[1] + y) * g.dims[0] + x)];
            if (l != labels[a] && std::find(near.begin(), near.end(), l) == near.end())
              near.push_back(l);
          }
      for (const int32_t l : near)
        for (size_t b = 0; b < n; ++b)
          if (labels[b] == l) candidates[b][a].push_back(static_cast<uint32_t>(i));
    }
  }
  std::vector<std::vector<char>> entering(n);
  for (size_t a = 0; a < n; ++a) entering[a].assign(surfaces[a]->points.size(), 0);
  for (size_t b = 0; b < n; ++b) {
    if (std::all_of(candidates[b].begin(), candidates[b].end(),
                    [](const auto& c) { return c.empty(); }))
      continue;
    auto normals = vtkSmartPointer<vtkPolyDataNormals>::New();
    normals->SetInputData(surface::to_polydata(*surfaces[b]));
    normals->ComputePointNormalsOn();
    normals->SplittingOff();
    normals->ConsistencyOff();
    normals->AutoOrientNormalsOff();
    normals->Update();
    auto distance = vtkSmartPointer<vtkImplicitPolyDataDistance>::New();
    distance->SetInput(normals->GetOutput());
    auto rays = vtkSmartPointer<vtkOBBTree>::New();
    rays->SetDataSet(normals->GetOutput());
    rays->BuildLocator();
    for (size_t a = 0; a < n; ++a)
      for (const uint32_t i : candidates[b][a]) {
        const auto& q = surfaces[a]->points[i];
        double p[3] = {q[0], q[1], q[2]};
        if (distance->EvaluateFunction(p) >= -depth_mm || rays->InsideOrOutside(p) != -1) continue;
        entering[a][i] = 1;
      }
  }
  LabelOverlap overlap;
  for (const auto& nodes : entering) {
    overlap.nodes += nodes.size();
    const auto inside = static_cast<size_t>(std::count(nodes.begin(), nodes.end(), 1));
    overlap.inside += inside;
    overlap.labels_entering += inside > 0;
  }
  return overlap;
}

}  // namespace labelmesh::testing
