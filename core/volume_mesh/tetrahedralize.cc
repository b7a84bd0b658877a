// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/tetrahedralize.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "core/util/disjoint_sets.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/vec3.h"
#include "core/volume_mesh/tetgen_call.h"

namespace labelmesh::volume_mesh {
namespace {

using geometry::Vec3;

// The pipeline times this work as its "tetgen" stage; progress says the same.
constexpr std::string_view kStage = "tetgen";

// The boundary as TetGen gets it: only the points some triangle uses, in input order.
struct Boundary {
  std::vector<Vec3> points;
  std::vector<std::array<uint32_t, 3>> triangles;
};

absl::StatusOr<Boundary> used_boundary(const surface::TriangleMesh& mesh, int32_t label) {
  const std::string what = cat("the surface of label ", label);
  if (mesh.points.size() < 4 || mesh.triangles.size() < 4) {
    return absl::InvalidArgumentError(cat(what, " has ", mesh.points.size(), " points and ",
                                          mesh.triangles.size(),
                                          " triangles; a closed surface needs at least 4 of each"));
  }
  constexpr uint32_t kUnused = UINT32_MAX;
  std::vector<uint32_t> new_index(mesh.points.size(), kUnused);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (uint32_t v : tri) {
      if (v >= mesh.points.size()) {
        return absl::InvalidArgumentError(
            cat(what, ": triangle ", t, " names point ", v, " of ", mesh.points.size()));
      }
      new_index[v] = 0;
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      return absl::InvalidArgumentError(cat(what, ": triangle ", t, " repeats a corner"));
    }
  }
  Boundary boundary;
  for (size_t v = 0; v < mesh.points.size(); ++v) {
    if (new_index[v] == kUnused) continue;
    new_index[v] = static_cast<uint32_t>(boundary.points.size());
    boundary.points.push_back(mesh.points[v]);
  }
  if (boundary.points.size() < 4) {
    return absl::InvalidArgumentError(
        cat(what, ": its triangles use ", boundary.points.size(), " points; at least 4 needed"));
  }
  boundary.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    boundary.triangles.push_back({new_index[t[0]], new_index[t[1]], new_index[t[2]]});
  return boundary;
}

// Six times the volume the boundary encloses (divergence theorem); negative when wound inwards.
double six_enclosed_volume(const Boundary& boundary) {
  double sum = 0;
  for (const auto& t : boundary.triangles) {
    sum += geometry::dot(boundary.points[t[0]],
                         geometry::cross(boundary.points[t[1]], boundary.points[t[2]]));
  }
  return sum;
}

size_t component_count(const Boundary& boundary) {
  geometry::DisjointSets sets(boundary.points.size());
  for (const auto& t : boundary.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  size_t count = 0;
  for (uint32_t v = 0; v < boundary.points.size(); ++v) count += sets.find(v) == v;
  return count;
}

std::array<int, 4> out_tet(const tetgenio& out, size_t t) {
  const int* v = out.tetrahedronlist + 4 * t;
  return {v[0], v[1], v[2], v[3]};
}

double out_volume6(const tetgenio& out, const std::array<int, 4>& v) {
  using geometry::cross, geometry::dot, geometry::sub;
  const Vec3 p0 = tetgen_point(out, v[0]);
  return dot(sub(tetgen_point(out, v[1]), p0),
             cross(sub(tetgen_point(out, v[2]), p0), sub(tetgen_point(out, v[3]), p0)));
}

// Points inside the cavities of a nested boundary. TetGen keeps every region the boundary
// encloses; only hole points make it carve one out. From a plain constrained tetrahedralization
// of the boundary (`cdt`, run with -p), tetrahedra are grouped into regions that no boundary face
// separates; a region is material when its tetrahedra lie behind the outward normals of the
// triangles around it, and a cavity when they lie in front. Each cavity yields the centroid of
// its largest tetrahedron, a point strictly inside it.
absl::StatusOr<std::vector<Vec3>> cavity_points(const Boundary& boundary, const tetgenio& cdt,
                                                int32_t label) {
  const size_t tet_count = static_cast<size_t>(cdt.numberoftetrahedra);
  struct Face {
    std::array<int, 3> key;  // sorted output point indices
    uint32_t tet;
    uint8_t across;  // local index of the vertex opposite the face
  };
  std::vector<Face> faces;
  faces.reserve(4 * tet_count);
  for (size_t t = 0; t < tet_count; ++t) {
    const auto v = out_tet(cdt, t);
    for (uint8_t across = 0; across < 4; ++across) {
      std::array<int, 3> key{};
      for (int k = 0, j = 0; k < 4; ++k) {
        if (k != across) key[j++] = v[k];
      }
      std::sort(key.begin(), key.end());
      faces.push_back({key, static_cast<uint32_t>(t), across});
    }
  }
  const auto by_key = [](const Face& a, const Face& b) {
    return std::tie(a.key, a.tet) < std::tie(b.key, b.tet);
  };
  std::sort(faces.begin(), faces.end(), by_key);

  // Output faces on the boundary, each with the input triangle it lies in.
  std::vector<std::pair<std::array<int, 3>, int>> constrained;
  for (int i = 0; i < cdt.numberoftrifaces; ++i) {
    const int marker = cdt.trifacemarkerlist != nullptr ? cdt.trifacemarkerlist[i] : 0;
    if (marker < 1 || static_cast<size_t>(marker) > boundary.triangles.size()) continue;
    std::array<int, 3> key{cdt.trifacelist[3 * i], cdt.trifacelist[3 * i + 1],
                           cdt.trifacelist[3 * i + 2]};
    std::sort(key.begin(), key.end());
    constrained.push_back({key, marker - 1});
  }
  std::sort(constrained.begin(), constrained.end());
  const auto is_constrained = [&](const std::array<int, 3>& key) {
    const auto it = std::lower_bound(constrained.begin(), constrained.end(),
                                     std::pair<std::array<int, 3>, int>{key, -1});
    return it != constrained.end() && it->first == key;
  };

  geometry::DisjointSets regions(tet_count);
  for (size_t i = 0; i + 1 < faces.size(); ++i) {
    if (faces[i].key == faces[i + 1].key && !is_constrained(faces[i].key))
      regions.unite(faces[i].tet, faces[i + 1].tet);
  }

  // Votes per region root: +1 for each boundary face it lies behind, -1 in front.
  std::vector<int64_t> votes(tet_count, 0);
  for (const auto& [key, triangle] : constrained) {
    const auto& tri = boundary.triangles[triangle];
    const Vec3& a = boundary.points[tri[0]];
    const Vec3 normal = geometry::cross(geometry::sub(boundary.points[tri[1]], a),
                                        geometry::sub(boundary.points[tri[2]], a));
    Face probe{key, 0, 0};
    for (auto it = std::lower_bound(faces.begin(), faces.end(), probe, by_key);
         it != faces.end() && it->key == key; ++it) {
      const int opposite = out_tet(cdt, it->tet)[it->across];
      const double side = geometry::dot(normal, geometry::sub(tetgen_point(cdt, opposite), a));
      if (side != 0) votes[regions.find(it->tet)] += side < 0 ? 1 : -1;
    }
  }

  bool any_material = false;
  std::vector<double> largest(tet_count, -1);  // per cavity root: volume of the chosen tet
  std::vector<Vec3> holes_by_root(tet_count);
  for (size_t t = 0; t < tet_count; ++t) {
    const uint32_t root = regions.find(static_cast<uint32_t>(t));
    if (votes[root] > 0) any_material = true;
    if (votes[root] >= 0) continue;
    const auto v = out_tet(cdt, t);
    const double volume6 = std::abs(out_volume6(cdt, v));
    if (volume6 <= largest[root]) continue;
    largest[root] = volume6;
    Vec3 centroid{0, 0, 0};
    for (int k = 0; k < 4; ++k) centroid = geometry::add(centroid, tetgen_point(cdt, v[k]));
    holes_by_root[root] = geometry::scale(centroid, 0.25);
  }
  if (!any_material) {
    return absl::FailedPreconditionError(
        cat("the surface of label ", label,
            " encloses no material: it is wound inwards (normals must point out)"));
  }
  std::vector<Vec3> holes;
  for (size_t root = 0; root < tet_count; ++root) {
    if (largest[root] >= 0) holes.push_back(holes_by_root[root]);
  }
  return holes;
}

absl::StatusOr<TetMesh> run(const surface::TriangleMesh& mesh, int32_t label,
                            const TetgenParams& params, const std::vector<Vec3>* known_holes,
                            const RunContext& context, TetgenFigures& figures) {
  LABELMESH_RETURN_IF_ERROR(check_tetgen_params(params));
  const std::string what = cat("the surface of label ", label);
  LABELMESH_ASSIGN_OR_RETURN(auto boundary, used_boundary(mesh, label));
  figures.input_points = boundary.points.size();
  figures.input_triangles = boundary.triangles.size();
  if (six_enclosed_volume(boundary) <= 0) {
    return absl::FailedPreconditionError(
        cat("the surface of label ", label,
            " encloses no volume: it is wound inwards or flat (normals must point out)"));
  }
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  context.report(kStage, 0);

  tetgenio in;
  fill_triangle_plc(boundary.points, boundary.triangles, in);

  // -d reports intersecting facets instead of failing, which TetGen 1.5.0 cannot do safely.
  {
    tetgenio check;
    LABELMESH_RETURN_IF_ERROR(run_tetgen("pdzQ", in, check, what));
    if (check.numberoftrifaces > 0) {
      return absl::FailedPreconditionError(cat("tetgen: the surface of label ", label,
                                               " intersects itself (", check.numberoftrifaces,
                                               " of its triangles cross others)"));
    }
  }
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  context.report(kStage, 0.2);

  if (known_holes != nullptr || component_count(boundary) > 1) {
    absl::StatusOr<std::vector<Vec3>> holes;
    if (known_holes != nullptr) {
      holes = *known_holes;
    } else {
      tetgenio cdt;
      LABELMESH_RETURN_IF_ERROR(run_tetgen("pzQ", in, cdt, what));
      holes = cavity_points(boundary, cdt, label);
    }
    if (!holes.ok()) return holes.status();
    if (!holes->empty()) {
      in.holelist = new REAL[3 * holes->size()];
      in.numberofholes = static_cast<int>(holes->size());
      for (size_t i = 0; i < holes->size(); ++i) {
        for (int k = 0; k < 3; ++k) in.holelist[3 * i + k] = (*holes)[i][k];
      }
    }
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    context.report(kStage, 0.4);
  }

  const std::string switches = tetgen_quality_switches(params) + "zQ";
  tetgenio out;
  LABELMESH_RETURN_IF_ERROR(run_tetgen(switches, in, out, what));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  if (out.numberofcorners != 4 || out.numberoftetrahedra <= 0 || out.tetrahedronlist == nullptr) {
    return absl::InternalError(cat("tetgen: produced no tetrahedra for label ", label));
  }
  const size_t tet_count = static_cast<size_t>(out.numberoftetrahedra);
  const size_t out_points = static_cast<size_t>(out.numberofpoints);
  constexpr uint32_t kUnused = UINT32_MAX;
  std::vector<uint32_t> new_index(out_points, kUnused);
  for (size_t t = 0; t < tet_count; ++t) {
    for (int v : out_tet(out, t)) {
      if (v < 0 || static_cast<size_t>(v) >= out_points) {
        return absl::InternalError(cat("tetgen: tetrahedron ", t, " names point ", v, " of ",
                                       out_points, " for label ", label));
      }
      new_index[v] = 0;
    }
  }
  TetMesh result;
  for (size_t v = 0; v < out_points; ++v) {
    if (new_index[v] == kUnused) continue;
    new_index[v] = static_cast<uint32_t>(result.points.size());
    result.points.push_back(tetgen_point(out, static_cast<int>(v)));
  }
  // TetGen 1.5 already writes tetrahedra in VTK's orientation (checked on its output: every
  // dot(p1 - p0, (p2 - p0) x (p3 - p0)) is positive), so corners are copied in order. The check
  // below keeps any inverted or flat tetrahedron from leaving this function.
  result.tetrahedra.reserve(tet_count);
  for (size_t t = 0; t < tet_count; ++t) {
    const auto v = out_tet(out, t);
    const double volume6 = out_volume6(out, v);
    if (!(volume6 > 0)) {
      return absl::InternalError(cat("tetgen: tetrahedron ", t, " of label ", label, " has volume ",
                                     volume6 / 6, " mm³; all must be positive"));
    }
    result.tetrahedra.push_back(
        {new_index[v[0]], new_index[v[1]], new_index[v[2]], new_index[v[3]]});
  }
  result.labels.assign(tet_count, label);
  figures.tetrahedra = tet_count;
  figures.steiner_points =
      result.points.size() > figures.input_points ? result.points.size() - figures.input_points : 0;
  context.report(kStage, 1);
  return result;
}

}  // namespace

absl::StatusOr<TetMesh> tetrahedralize(const surface::TriangleMesh& boundary, int32_t label,
                                       const TetgenParams& params, const RunContext& context,
                                       TetgenFigures& figures) {
  return tetrahedralize_around(boundary, label, params, nullptr, context, figures);
}

absl::StatusOr<TetMesh> tetrahedralize_around(const surface::TriangleMesh& boundary, int32_t label,
                                              const TetgenParams& params,
                                              const std::vector<std::array<double, 3>>* holes,
                                              const RunContext& context, TetgenFigures& figures) {
  const auto start = std::chrono::steady_clock::now();
  figures = TetgenFigures{};
  absl::StatusOr<TetMesh> result;
  try {
    result = run(boundary, label, params, holes, context, figures);
  } catch (const std::bad_alloc&) {
    result = absl::ResourceExhaustedError(
        cat("out of memory tetrahedralizing the surface of label ", label));
  } catch (...) {
    result = absl::InternalError(
        cat("unexpected failure tetrahedralizing the surface of label ", label));
  }
  figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace labelmesh::volume_mesh
