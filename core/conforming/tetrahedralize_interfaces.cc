// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/tetrahedralize_interfaces.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <map>
#include <new>
#include <string>
#include <unordered_map>

#include "core/util/disjoint_sets.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/vec3.h"
#include "core/volume_mesh/tetgen_call.h"

namespace labelmesh::conforming {
namespace {

using geometry::Vec3;
using volume_mesh::fill_triangle_plc;
using volume_mesh::run_tetgen;
using volume_mesh::tetgen_point;

constexpr std::string_view kStage = "tetgen";
constexpr std::string_view kWhat = "the labels' interface surface";

absl::Status check_surface(const InterfaceSurface& surface) {
  if (surface.points.size() < 4 || surface.triangles.size() < 4) {
    return absl::InvalidArgumentError(cat(kWhat, " has ", surface.points.size(), " points and ",
                                          surface.triangles.size(),
                                          " triangles; a closed surface needs at least 4 of each"));
  }
  if (surface.sides.size() != surface.triangles.size()) {
    return absl::InvalidArgumentError(cat(kWhat, " has ", surface.sides.size(), " label pairs for ",
                                          surface.triangles.size(), " triangles"));
  }
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    for (uint32_t v : tri) {
      if (v >= surface.points.size())
        return absl::InvalidArgumentError(cat(kWhat, ": triangle ", t, " names point ", v));
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return absl::InvalidArgumentError(cat(kWhat, ": triangle ", t, " repeats a corner"));
  }
  return absl::OkStatus();
}

const int* out_tet(const tetgenio& out, size_t t) { return out.tetrahedronlist + 4 * t; }

// A face's key: its three point indices, sorted, packed into 64 bits.
uint64_t face_key(int a, int b, int c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 42) | (static_cast<uint64_t>(b) << 21) |
         static_cast<uint64_t>(c);
}

constexpr int kMaxKeyedPoints = 1 << 21;

// Groups tetrahedra into regions that no constrained face separates, and
// gives each region the label its constrained faces say: the side of the
// interface triangle the region's tetrahedra lie on.
absl::StatusOr<std::vector<int32_t>> region_labels(const InterfaceSurface& surface,
                                                   const tetgenio& out, LabelledRegions& regions) {
  const size_t tet_count = static_cast<size_t>(out.numberoftetrahedra);
  // Constrained faces: key -> triangle index.
  std::unordered_map<uint64_t, int> constrained;
  constrained.reserve(static_cast<size_t>(out.numberoftrifaces));
  for (int f = 0; out.trifacemarkerlist != nullptr && f < out.numberoftrifaces; ++f) {
    const int marker = out.trifacemarkerlist[f];
    if (marker < 1 || static_cast<size_t>(marker) > surface.triangles.size()) continue;
    const int* v = out.trifacelist + 3 * f;
    constrained.emplace(face_key(v[0], v[1], v[2]), marker - 1);
  }
  geometry::DisjointSets sets(tet_count);
  for (size_t t = 0; t < tet_count; ++t) {
    const int* v = out_tet(out, t);
    for (int across = 0; across < 4; ++across) {
      const int neighbour = out.neighborlist[4 * t + across];
      if (neighbour < 0 || static_cast<size_t>(neighbour) < t) continue;
      const int a = v[(across + 1) % 4], b = v[(across + 2) % 4], c = v[(across + 3) % 4];
      if (!constrained.contains(face_key(a, b, c)))
        sets.unite(static_cast<uint32_t>(t), static_cast<uint32_t>(neighbour));
    }
  }
  // Votes: per region root, the labels its constrained faces give it.
  std::unordered_map<uint32_t, std::map<int32_t, size_t>> votes;
  for (size_t t = 0; t < tet_count; ++t) {
    const int* v = out_tet(out, t);
    for (int across = 0; across < 4; ++across) {
      const int a = v[(across + 1) % 4], b = v[(across + 2) % 4], c = v[(across + 3) % 4];
      const auto it = constrained.find(face_key(a, b, c));
      if (it == constrained.end()) continue;
      const auto& tri = surface.triangles[it->second];
      const Vec3& p0 = surface.points[tri[0]];
      const Vec3 normal = geometry::cross(geometry::sub(surface.points[tri[1]], p0),
                                          geometry::sub(surface.points[tri[2]], p0));
      const double side = geometry::dot(normal, geometry::sub(tetgen_point(out, v[across]), p0));
      if (side == 0) continue;
      const auto& sides = surface.sides[it->second];
      ++votes[sets.find(static_cast<uint32_t>(t))][side < 0 ? sides[0] : sides[1]];
    }
  }
  std::unordered_map<uint32_t, int32_t> label_of_root;
  for (const auto& [root, counts] : votes) {
    const auto best =
        std::max_element(counts.begin(), counts.end(),
                         [](const auto& x, const auto& y) { return x.second < y.second; });
    label_of_root[root] = best->first;
    for (const auto& [label, count] : counts) {
      if (label != best->first) regions.mislabelled_faces += count;
    }
    ++regions.regions;
    if (best->first == kOutside) ++regions.outside_regions;
  }
  std::vector<int32_t> labels(tet_count, kOutside);
  for (size_t t = 0; t < tet_count; ++t) {
    const auto it = label_of_root.find(sets.find(static_cast<uint32_t>(t)));
    if (it == label_of_root.end()) {
      return absl::FailedPreconditionError(
          cat("tetgen: a region of ", kWhat, " has no interface triangle around it"));
    }
    labels[t] = it->second;
  }
  if (regions.mislabelled_faces > 0) {
    return absl::FailedPreconditionError(cat("tetgen: ", regions.mislabelled_faces, " faces of ",
                                             kWhat,
                                             " disagree with the label of the region behind them"));
  }
  return labels;
}

absl::StatusOr<volume_mesh::TetMesh> labelled_mesh(const InterfaceSurface& surface,
                                                   const tetgenio& out, LabelledRegions& regions) {
  if (out.numberofcorners != 4 || out.numberoftetrahedra <= 0 || out.neighborlist == nullptr) {
    return absl::InternalError(cat("tetgen: produced no tetrahedra for ", kWhat));
  }
  if (out.numberofpoints >= kMaxKeyedPoints) {
    return absl::ResourceExhaustedError(cat("tetgen: ", out.numberofpoints, " points for ", kWhat,
                                            "; at most ", kMaxKeyedPoints - 1, " are supported"));
  }
  LABELMESH_ASSIGN_OR_RETURN(auto labels, region_labels(surface, out, regions));

  const size_t tet_count = static_cast<size_t>(out.numberoftetrahedra);
  const size_t out_points = static_cast<size_t>(out.numberofpoints);
  // Points some labelled tetrahedron uses keep their order, so the surface's
  // points (TetGen's first) keep their indices.
  constexpr uint32_t kUnused = UINT32_MAX;
  std::vector<uint32_t> new_index(out_points, kUnused);
  for (size_t t = 0; t < tet_count; ++t) {
    if (labels[t] == kOutside) continue;
    const int* v = out_tet(out, t);
    for (int k = 0; k < 4; ++k) {
      if (v[k] < 0 || static_cast<size_t>(v[k]) >= out_points)
        return absl::InternalError(cat("tetgen: tetrahedron ", t, " names point ", v[k]));
      new_index[static_cast<size_t>(v[k])] = 0;
    }
  }
  volume_mesh::TetMesh mesh;
  for (size_t p = 0; p < out_points; ++p) {
    if (new_index[p] == kUnused) continue;
    new_index[p] = static_cast<uint32_t>(mesh.points.size());
    mesh.points.push_back(tetgen_point(out, static_cast<int>(p)));
  }
  for (size_t t = 0; t < tet_count; ++t) {
    if (labels[t] == kOutside) continue;
    const int* v = out_tet(out, t);
    mesh.tetrahedra.push_back({new_index[v[0]], new_index[v[1]], new_index[v[2]], new_index[v[3]]});
    mesh.labels.push_back(labels[t]);
    if (!(volume_mesh::signed_volume(mesh, mesh.tetrahedra.size() - 1) > 0)) {
      return absl::InternalError(cat("tetgen: tetrahedron ", t, " of ", kWhat,
                                     " is flat or inverted; all must have positive volume"));
    }
  }
  return mesh;
}

}  // namespace

absl::StatusOr<std::vector<uint32_t>> crossing_points(const InterfaceSurface& surface) {
  LABELMESH_RETURN_IF_ERROR(check_surface(surface));
  tetgenio in;
  fill_triangle_plc(surface.points, surface.triangles, in);
  tetgenio check;
  LABELMESH_RETURN_IF_ERROR(run_tetgen("pdzQ", in, check, kWhat));
  std::vector<uint32_t> points;
  for (int f = 0; f < 3 * check.numberoftrifaces; ++f)
    points.push_back(static_cast<uint32_t>(check.trifacelist[f]));
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

absl::StatusOr<volume_mesh::TetMesh> tetrahedralize_interfaces(
    const InterfaceSurface& surface, const volume_mesh::TetgenParams& params,
    const RunContext& context, volume_mesh::TetgenFigures& figures, LabelledRegions& regions) {
  const auto start = std::chrono::steady_clock::now();
  figures = volume_mesh::TetgenFigures{};
  regions = LabelledRegions{};
  LABELMESH_RETURN_IF_ERROR(volume_mesh::check_tetgen_params(params));
  LABELMESH_RETURN_IF_ERROR(check_surface(surface));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  context.report(kStage, 0);
  figures.input_points = surface.points.size();
  figures.input_triangles = surface.triangles.size();

  absl::StatusOr<volume_mesh::TetMesh> result;
  try {
    tetgenio in;
    fill_triangle_plc(surface.points, surface.triangles, in);
    tetgenio out;
    // -n: neighbours, to find the regions; the faces TetGen lists are the constrained ones, marked.
    const std::string switches = volume_mesh::tetgen_quality_switches(params) + "nzQ";
    LABELMESH_RETURN_IF_ERROR(run_tetgen(switches, in, out, kWhat));
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    result = labelled_mesh(surface, out, regions);
  } catch (const std::bad_alloc&) {
    result = absl::ResourceExhaustedError(cat("out of memory meshing ", kWhat));
  }
  if (result.ok()) {
    figures.tetrahedra = result->tetrahedra.size();
    figures.steiner_points = result->points.size() > figures.input_points
                                 ? result->points.size() - figures.input_points
                                 : 0;
  }
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  context.report(kStage, 1);
  return result;
}

}  // namespace labelmesh::conforming
