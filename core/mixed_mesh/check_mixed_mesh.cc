// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/check_mixed_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "core/mixed_mesh/mixed_faces.h"
#include "core/util/text.h"
#include "core/util/vec3.h"

namespace labelmesh::mixed_mesh {
namespace {

using geometry::Vec3;

bool known_type(CellType type) {
  return type == CellType::kTetra || type == CellType::kPyramid || type == CellType::kWedge ||
         type == CellType::kHexahedron;
}

// True when `b` runs through the points of `a` backwards: the same face seen from its other side.
bool opposite_windings(const CellFace& a, const CellFace& b) {
  if (a.size != b.size) return false;
  const int n = a.size;
  const auto start = std::find(b.points.begin(), b.points.begin() + n, a.points[0]);
  if (start == b.points.begin() + n) return false;
  const int at = static_cast<int>(start - b.points.begin());
  for (int k = 1; k < n; ++k)
    if (a.points[k] != b.points[(at - k + n) % n]) return false;
  return true;
}

// The three-point subsets of a quad's points, sorted, padded like CellFace::key.
std::array<std::array<uint32_t, 4>, 4> quad_corner_triples(const CellFace& quad) {
  const auto key = quad.key();
  std::array<std::array<uint32_t, 4>, 4> triples;
  for (int omit = 0; omit < 4; ++omit) {
    int k = 0;
    for (int i = 0; i < 4; ++i)
      if (i != omit) triples[omit][k++] = key[i];
    triples[omit][3] = CellFace::kNone;
  }
  return triples;
}

// Marks boundary triangles that lie on three corners of a boundary quad, and those quads: a quad
// face against a neighbour's two triangles (a diagonal split) shares no point set with them.
void mark_quads_against_triangles(const std::vector<CellFace>& faces,
                                  const std::vector<size_t>& boundary, std::vector<bool>& bad) {
  std::map<std::array<uint32_t, 4>, std::vector<size_t>> quads_by_triple;
  for (size_t f : boundary) {
    if (faces[f].size != 4) continue;
    for (const auto& triple : quad_corner_triples(faces[f])) quads_by_triple[triple].push_back(f);
  }
  for (size_t f : boundary) {
    if (faces[f].size != 3) continue;
    const auto found = quads_by_triple.find(faces[f].key());
    if (found == quads_by_triple.end()) continue;
    bad[f] = true;
    for (size_t quad : found->second) bad[quad] = true;
  }
}

size_t count_open_edges(const std::vector<CellFace>& faces, const std::vector<size_t>& boundary) {
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (size_t f : boundary) {
    const CellFace& face = faces[f];
    for (int k = 0; k < face.size; ++k) {
      const uint32_t a = face.points[k];
      const uint32_t b = face.points[(k + 1) % face.size];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  size_t open = 0;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) ++open;
    i = j;
  }
  return open;
}

size_t count_duplicate_points(const MixedMesh& mesh) {
  std::vector<uint32_t> order(mesh.points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return mesh.points[a] < mesh.points[b]; });
  size_t duplicates = 0;
  for (size_t i = 1; i < order.size(); ++i)
    if (mesh.points[order[i]] == mesh.points[order[i - 1]]) ++duplicates;
  return duplicates;
}

// 1/3 ∫ x·n dA over the bilinear quad p0 p1 p2 p3, with 2x2 Gauss points: the integrand is of
// degree 2 in each parameter, so the rule is exact.
double quad_flux(const std::array<Vec3, 4>& p) {
  const double g = 0.5 / std::sqrt(3.0);
  double sum = 0;
  for (double u : {0.5 - g, 0.5 + g}) {
    for (double v : {0.5 - g, 0.5 + g}) {
      Vec3 x{}, du{}, dv{};
      const double w[4] = {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
      const double wu[4] = {-(1 - v), 1 - v, v, -v};
      const double wv[4] = {-(1 - u), -u, u, 1 - u};
      for (int i = 0; i < 4; ++i) {
        x = geometry::add(x, geometry::scale(p[i], w[i]));
        du = geometry::add(du, geometry::scale(p[i], wu[i]));
        dv = geometry::add(dv, geometry::scale(p[i], wv[i]));
      }
      sum += 0.25 * geometry::dot(x, geometry::cross(du, dv));
    }
  }
  return sum / 3;
}

struct CellFigures {
  double jacobian_ratio;
  double quality;
  double min_corner_jacobian;
};

template <size_t N>
double min_of(const std::array<double, N>& values) {
  return *std::min_element(values.begin(), values.end());
}

CellFigures measure_hexahedron(const quality::Hex& p) {
  const double jr = quality::hexahedron_jacobian_ratio(p);
  return {jr, jr, min_of(quality::hexahedron_corner_jacobians(p))};
}

CellFigures measure_wedge(const quality::Wedge& p) {
  const double jr = quality::wedge_jacobian_ratio(p);
  return {jr, jr, min_of(quality::wedge_corner_jacobians(p))};
}

CellFigures measure_pyramid(const quality::Pyramid& p) {
  const double jr = quality::pyramid_jacobian_ratio(p);
  return {jr, jr, min_of(quality::pyramid_corner_jacobians(p))};
}

CellFigures measure_tetra(const quality::Tet& p) {
  const double corner = 6 * quality::tetra_signed_volume(p);
  const std::array<double, 4> corners{corner, corner, corner, corner};
  return {quality::jacobian_ratio(corners), quality::tetra_quality(p), corner};
}

}  // namespace

absl::Status check_mixed_mesh(const MixedMesh& mesh) {
  if (mesh.cells.size() != mesh.types.size() || mesh.labels.size() != mesh.types.size()) {
    return absl::InvalidArgumentError(cat("the mesh has ", mesh.types.size(), " cell types, ",
                                          mesh.cells.size(), " cells and ", mesh.labels.size(),
                                          " labels"));
  }
  for (size_t c = 0; c < mesh.size(); ++c) {
    if (!known_type(mesh.types[c])) {
      return absl::InvalidArgumentError(
          cat("cell ", c, " has the unknown type ", static_cast<int>(mesh.types[c])));
    }
    const int n = node_count(mesh.types[c]);
    const auto& nodes = mesh.cells[c];
    for (int k = 0; k < n; ++k) {
      if (nodes[k] >= mesh.points.size()) {
        return absl::InvalidArgumentError(cat("cell ", c, " names point ", nodes[k],
                                              " but the mesh has ", mesh.points.size(), " points"));
      }
      if (std::find(nodes.begin(), nodes.begin() + k, nodes[k]) != nodes.begin() + k) {
        return absl::InvalidArgumentError(cat("cell ", c, " names point ", nodes[k], " twice"));
      }
    }
  }
  return absl::OkStatus();
}

Conformity check_conformity(const MixedMesh& mesh) {
  const std::vector<CellFace> faces = cell_faces(mesh);
  std::vector<std::pair<std::array<uint32_t, 4>, size_t>> keyed;
  keyed.reserve(faces.size());
  for (size_t f = 0; f < faces.size(); ++f) keyed.emplace_back(faces[f].key(), f);
  std::sort(keyed.begin(), keyed.end());

  Conformity result;
  std::vector<size_t> boundary;
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i + 1;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) ++j;
    if (j - i == 1) {
      boundary.push_back(keyed[i].second);
    } else if (j - i == 2 &&
               opposite_windings(faces[keyed[i].second], faces[keyed[i + 1].second])) {
      ++result.interior_faces;
    } else {
      ++result.nonconforming_faces;
    }
    i = j;
  }
  std::vector<bool> bad(faces.size(), false);
  mark_quads_against_triangles(faces, boundary, bad);
  std::erase_if(boundary, [&](size_t f) {
    if (!bad[f]) return false;
    ++result.nonconforming_faces;
    return true;
  });
  result.boundary_faces = boundary.size();
  result.open_boundary_edges = count_open_edges(faces, boundary);
  result.duplicate_points = count_duplicate_points(mesh);
  return result;
}

double cell_signed_volume(const MixedMesh& mesh, size_t cell) {
  const auto& nodes = mesh.cells[cell];
  // Relative to the first node, so the flux terms stay small and exact for any offset.
  const Vec3 origin = mesh.points[nodes[0]];
  const auto at = [&](uint8_t local) { return geometry::sub(mesh.points[nodes[local]], origin); };
  double volume = 0;
  for (const LocalFace& face : local_faces(mesh.types[cell])) {
    if (face.size == 3) {
      const Vec3 a = at(face.nodes[0]), b = at(face.nodes[1]), c = at(face.nodes[2]);
      volume += geometry::dot(a, geometry::cross(b, c)) / 6;
    } else {
      volume +=
          quad_flux({at(face.nodes[0]), at(face.nodes[1]), at(face.nodes[2]), at(face.nodes[3])});
    }
  }
  return volume;
}

MixedQuality measure_mixed_mesh(const MixedMesh& mesh) {
  MixedQuality result;
  result.jacobian_ratio.reserve(mesh.size());
  result.quality.reserve(mesh.size());
  double jacobian_ratio_sum = 0;
  for (size_t c = 0; c < mesh.size(); ++c) {
    CellFigures figures{};
    switch (mesh.types[c]) {
      case CellType::kHexahedron: {
        const auto p = cell_points<8>(mesh, c);
        figures = measure_hexahedron(p);
        const double scaled = quality::hexahedron_scaled_jacobian(p);
        result.scaled_jacobian_min = std::min(result.scaled_jacobian_min.value_or(scaled), scaled);
        ++result.hexahedra;
        break;
      }
      case CellType::kWedge:
        figures = measure_wedge(cell_points<6>(mesh, c));
        ++result.wedges;
        break;
      case CellType::kPyramid: {
        const auto p = cell_points<5>(mesh, c);
        figures = measure_pyramid(p);
        const double aspect = quality::pyramid_signed_aspect_ratio(p);
        result.pyramid_aspect_ratio_min =
            std::min(result.pyramid_aspect_ratio_min.value_or(aspect), aspect);
        ++result.pyramids;
        break;
      }
      case CellType::kTetra: {
        const auto p = cell_points<4>(mesh, c);
        figures = measure_tetra(p);
        result.tetra_summary.add(figures.quality);
        result.tetra_summary.add_dihedral_range(quality::tetra_dihedral_range_deg(p));
        ++result.tetrahedra;
        break;
      }
    }
    result.jacobian_ratio.push_back(figures.jacobian_ratio);
    result.quality.push_back(figures.quality);
    result.cell_summary.add(figures.quality);
    result.jacobian_ratio_min = std::min(result.jacobian_ratio_min, figures.jacobian_ratio);
    jacobian_ratio_sum += figures.jacobian_ratio;
    if (!(figures.min_corner_jacobian > 0)) ++result.invalid;
    result.volume_mm3 += cell_signed_volume(mesh, c);
  }
  if (mesh.size() > 0) result.jacobian_ratio_mean = jacobian_ratio_sum / double(mesh.size());
  return result;
}

}  // namespace labelmesh::mixed_mesh
