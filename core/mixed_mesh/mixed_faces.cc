// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/mixed_faces.h"

#include <algorithm>
#include <tuple>

namespace labelmesh::mixed_mesh {
namespace {

// VTK 9.1's face tables (vtkHexahedron.cxx, vtkWedge.cxx, vtkPyramid.cxx, vtkTetra.cxx, read
// through their static GetFaceArray; tests/mixed_mesh compares them). Each face's right-hand
// normal points out of a cell in VTK's node ordering.
constexpr LocalFace kHexahedron[] = {{4, {0, 4, 7, 3}}, {4, {1, 2, 6, 5}}, {4, {0, 1, 5, 4}},
                                     {4, {3, 7, 6, 2}}, {4, {0, 3, 2, 1}}, {4, {4, 5, 6, 7}}};
constexpr LocalFace kWedge[] = {
    {3, {0, 1, 2, 0}}, {3, {3, 5, 4, 0}}, {4, {0, 3, 4, 1}}, {4, {1, 4, 5, 2}}, {4, {2, 5, 3, 0}}};
constexpr LocalFace kPyramid[] = {
    {4, {0, 3, 2, 1}}, {3, {0, 1, 4, 0}}, {3, {1, 2, 4, 0}}, {3, {2, 3, 4, 0}}, {3, {3, 0, 4, 0}}};
constexpr LocalFace kTetra[] = {
    {3, {0, 1, 3, 0}}, {3, {1, 2, 3, 0}}, {3, {2, 0, 3, 0}}, {3, {0, 2, 1, 0}}};

}  // namespace

std::span<const LocalFace> local_faces(CellType type) {
  switch (type) {
    case CellType::kHexahedron:
      return kHexahedron;
    case CellType::kWedge:
      return kWedge;
    case CellType::kPyramid:
      return kPyramid;
    case CellType::kTetra:
      return kTetra;
  }
  return {};
}

std::array<uint8_t, 4> hexahedron_face_inward(int f) {
  const auto& outward = kHexahedron[f].nodes;
  return {outward[3], outward[2], outward[1], outward[0]};
}

std::array<uint32_t, 4> CellFace::key() const {
  std::array<uint32_t, 4> sorted = points;
  if (size == 3) sorted[3] = kNone;
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

std::vector<CellFace> cell_faces(const MixedMesh& mesh) {
  std::vector<CellFace> faces;
  faces.reserve(6 * mesh.size());
  for (size_t c = 0; c < mesh.size(); ++c) {
    const auto& nodes = mesh.cells[c];
    const auto local = local_faces(mesh.types[c]);
    for (size_t f = 0; f < local.size(); ++f) {
      CellFace face{static_cast<uint32_t>(c), static_cast<uint8_t>(f), local[f].size, {}};
      for (int k = 0; k < 4; ++k)
        face.points[k] = k < local[f].size ? nodes[local[f].nodes[k]] : CellFace::kNone;
      faces.push_back(face);
    }
  }
  return faces;
}

std::vector<CellFace> label_boundary_faces(const MixedMesh& mesh) {
  struct Entry {
    int32_t label;
    std::array<uint32_t, 4> key;
    size_t face;  // index into `faces`
  };
  const std::vector<CellFace> faces = cell_faces(mesh);
  std::vector<Entry> entries;
  entries.reserve(faces.size());
  for (size_t i = 0; i < faces.size(); ++i)
    entries.push_back({mesh.labels[faces[i].cell], faces[i].key(), i});
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.label, a.key, a.face) < std::tie(b.label, b.key, b.face);
  });
  // A (label, key) seen once is a face of the label's boundary.
  std::vector<CellFace> boundary;
  for (size_t i = 0; i < entries.size();) {
    size_t j = i + 1;
    while (j < entries.size() && entries[j].label == entries[i].label &&
           entries[j].key == entries[i].key)
      ++j;
    if (j - i == 1) boundary.push_back(faces[entries[i].face]);
    i = j;
  }
  std::sort(boundary.begin(), boundary.end(), [&](const CellFace& a, const CellFace& b) {
    return std::tuple(mesh.labels[a.cell], a.cell, a.local) <
           std::tuple(mesh.labels[b.cell], b.cell, b.local);
  });
  return boundary;
}

}  // namespace labelmesh::mixed_mesh
