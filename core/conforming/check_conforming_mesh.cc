// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/check_conforming_mesh.h"

#include <algorithm>
#include <cmath>

#include "core/util/text.h"
#include "core/util/vec3.h"

namespace labelmesh::conforming {

using volume_mesh::TetMesh;

double ConformityCheck::volume_gap_fraction() const {
  return union_volume_mm3 > 0 ? std::abs(label_volume_sum_mm3 - union_volume_mm3) / union_volume_mm3
                              : 0;
}

// Summing a million signed volumes in double loses far less than this.
constexpr double kVolumeTolerance = 1e-9;

bool ConformityCheck::ok() const { return failures().empty(); }

std::string ConformityCheck::failures() const {
  std::string text;
  const auto add = [&](size_t count, std::string_view what) {
    if (count == 0) return;
    if (!text.empty()) text += "; ";
    text += cat(count, " ", what);
  };
  add(overshared_faces, "faces shared by three or more tetrahedra");
  add(inverted_tetrahedra, "flat or inverted tetrahedra");
  add(duplicate_points, "points repeated at the same coordinates");
  add(unused_points, "points no tetrahedron uses");
  add(open_boundary_edges, "open edges on the outer boundary");
  add(unlabelled_tetrahedra, "tetrahedra without a label");
  if (tetrahedra == 0) add(1, "mesh without tetrahedra");
  if (volume_gap_fraction() > kVolumeTolerance) {
    if (!text.empty()) text += "; ";
    text += cat("the labels' volumes add up to ", label_volume_sum_mm3,
                " mm³ but the outer boundary encloses ", union_volume_mm3, " mm³");
  }
  return text;
}

ConformityCheck check_conforming_mesh(const TetMesh& mesh) {
  ConformityCheck check;
  check.tetrahedra = mesh.tetrahedra.size();
  check.points = mesh.points.size();
  std::vector<bool> used(mesh.points.size(), false);
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    for (uint32_t p : mesh.tetrahedra[t]) used[p] = true;
    const double volume = volume_mesh::signed_volume(mesh, t);
    if (!(volume > 0)) ++check.inverted_tetrahedra;
    check.label_volume_sum_mm3 += volume;
    if (mesh.labels[t] == 0) ++check.unlabelled_tetrahedra;
  }
  check.unused_points = static_cast<size_t>(std::count(used.begin(), used.end(), false));

  std::vector<std::array<double, 3>> sorted_points = mesh.points;
  std::sort(sorted_points.begin(), sorted_points.end());
  for (size_t i = 1; i < sorted_points.size(); ++i)
    check.duplicate_points += sorted_points[i] == sorted_points[i - 1];

  std::vector<std::array<int32_t, 2>> pairs;
  std::vector<std::pair<uint32_t, uint32_t>> outer_edges;
  volume_mesh::for_each_face(mesh, [&](const volume_mesh::FaceUse* uses, size_t count) {
    if (count > 2) {
      ++check.overshared_faces;
    } else if (count == 2) {
      const int32_t a = mesh.labels[uses[0].tet];
      const int32_t b = mesh.labels[uses[1].tet];
      if (a == b) {
        ++check.interior_faces;
      } else {
        ++check.interface_faces;
        pairs.push_back({std::min(a, b), std::max(a, b)});
      }
    } else {
      ++check.outer_faces;
      pairs.push_back({mesh.labels[uses[0].tet], 0});
      const auto p = volume_mesh::face_points(mesh, uses[0]);
      // Relative to the first point, to keep the sum's rounding small.
      const auto& o = mesh.points.front();
      check.union_volume_mm3 +=
          geometry::dot(geometry::sub(mesh.points[p[0]], o),
                        geometry::cross(geometry::sub(mesh.points[p[1]], o),
                                        geometry::sub(mesh.points[p[2]], o))) /
          6;
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = p[k], v = p[(k + 1) % 3];
        outer_edges.push_back({std::min(u, v), std::max(u, v)});
      }
    }
  });
  std::sort(pairs.begin(), pairs.end());
  check.interfaces = static_cast<size_t>(std::unique(pairs.begin(), pairs.end()) - pairs.begin());
  std::sort(outer_edges.begin(), outer_edges.end());
  for (size_t i = 0; i < outer_edges.size();) {
    size_t j = i + 1;
    while (j < outer_edges.size() && outer_edges[j] == outer_edges[i]) ++j;
    if ((j - i) % 2 != 0) ++check.open_boundary_edges;
    i = j;
  }
  return check;
}

}  // namespace labelmesh::conforming
