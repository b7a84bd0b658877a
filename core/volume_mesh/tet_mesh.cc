// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/tet_mesh.h"

#include <algorithm>
#include <tuple>

#include "core/quality/element_quality.h"
#include "core/util/text.h"
#include "core/util/vec3.h"

namespace labelmesh::volume_mesh {

void TetMesh::append(const TetMesh& other) {
  const auto offset = static_cast<uint32_t>(points.size());
  points.insert(points.end(), other.points.begin(), other.points.end());
  tetrahedra.reserve(tetrahedra.size() + other.tetrahedra.size());
  for (const auto& t : other.tetrahedra)
    tetrahedra.push_back({t[0] + offset, t[1] + offset, t[2] + offset, t[3] + offset});
  labels.insert(labels.end(), other.labels.begin(), other.labels.end());
}

double signed_volume(const TetMesh& mesh, size_t t) {
  const auto& v = mesh.tetrahedra[t];
  return quality::tetra_signed_volume(
      {mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]], mesh.points[v[3]]});
}

const std::array<uint8_t, 3>& outward_face(uint8_t across) {
  // With node 3 on the positive side of triangle 0,1,2, each face below has its right-hand
  // normal pointing away from the node it omits.
  static constexpr std::array<std::array<uint8_t, 3>, 4> kFaces{
      {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
  return kFaces[across];
}

std::vector<BoundaryFace> label_boundary_faces(const TetMesh& mesh) {
  std::vector<BoundaryFace> faces;
  for_each_face(mesh, [&](const FaceUse* uses, size_t count) {
    for (size_t i = 0; i < count; ++i) {
      const int32_t label = mesh.labels[uses[i].tet];
      size_t same_label = 0;
      for (size_t j = 0; j < count; ++j) same_label += mesh.labels[uses[j].tet] == label;
      if (same_label == 1)
        faces.push_back({uses[i].tet, label, uses[i].across, face_points(mesh, uses[i])});
    }
  });
  std::sort(faces.begin(), faces.end(), [](const BoundaryFace& a, const BoundaryFace& b) {
    return std::tie(a.label, a.tet, a.across) < std::tie(b.label, b.tet, b.across);
  });
  return faces;
}

absl::Status check_tet_mesh(const TetMesh& mesh) {
  if (mesh.labels.size() != mesh.tetrahedra.size()) {
    return absl::InvalidArgumentError(cat("the mesh has ", mesh.tetrahedra.size(),
                                          " tetrahedra but ", mesh.labels.size(), " labels"));
  }
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    for (uint32_t v : mesh.tetrahedra[t]) {
      if (v >= mesh.points.size()) {
        return absl::InvalidArgumentError(cat("tetrahedron ", t, " names point ", v,
                                              " but the mesh has ", mesh.points.size(), " points"));
      }
    }
  }
  return absl::OkStatus();
}

void for_each_face(const TetMesh& mesh, const std::function<void(const FaceUse*, size_t)>& visit) {
  struct Entry {
    std::array<uint32_t, 3> key;  // sorted point indices
    FaceUse use;
  };
  std::vector<Entry> entries;
  entries.reserve(4 * mesh.tetrahedra.size());
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    for (uint8_t across = 0; across < 4; ++across) {
      const FaceUse use{static_cast<uint32_t>(t), across};
      std::array<uint32_t, 3> key = face_points(mesh, use);
      std::sort(key.begin(), key.end());
      entries.push_back({key, use});
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.key, a.use.tet, a.use.across) < std::tie(b.key, b.use.tet, b.use.across);
  });
  std::vector<FaceUse> uses;
  for (size_t i = 0; i < entries.size();) {
    uses.clear();
    size_t j = i;
    for (; j < entries.size() && entries[j].key == entries[i].key; ++j)
      uses.push_back(entries[j].use);
    visit(uses.data(), uses.size());
    i = j;
  }
}

std::array<uint32_t, 3> face_points(const TetMesh& mesh, const FaceUse& use) {
  const auto& local = outward_face(use.across);
  const auto& tet = mesh.tetrahedra[use.tet];
  return {tet[local[0]], tet[local[1]], tet[local[2]]};
}

quality::QualitySummary summarise_quality(const TetMesh& mesh,
                                          std::vector<double>* per_tetrahedron) {
  quality::QualitySummary summary;
  if (per_tetrahedron != nullptr) {
    per_tetrahedron->clear();
    per_tetrahedron->reserve(mesh.tetrahedra.size());
  }
  for (const auto& v : mesh.tetrahedra) {
    const quality::Tet tet{mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]],
                           mesh.points[v[3]]};
    const double q = quality::tetra_quality(tet);
    if (per_tetrahedron != nullptr) per_tetrahedron->push_back(q);
    summary.add(q);
    summary.add_dihedral_range(quality::tetra_dihedral_range_deg(tet));
  }
  return summary;
}

std::vector<InterfaceFace> interface_faces(const TetMesh& mesh) {
  std::vector<InterfaceFace> faces;
  for_each_face(mesh, [&](const FaceUse* uses, size_t count) {
    if (count == 1) {
      faces.push_back(
          {face_points(mesh, uses[0]), {mesh.labels[uses[0].tet], 0}, uses[0].tet, uses[0].across});
    } else if (count == 2) {
      const FaceUse* a = &uses[0];
      const FaceUse* b = &uses[1];
      if (mesh.labels[a->tet] == mesh.labels[b->tet]) return;
      if (mesh.labels[b->tet] < mesh.labels[a->tet]) std::swap(a, b);
      faces.push_back(
          {face_points(mesh, *a), {mesh.labels[a->tet], mesh.labels[b->tet]}, a->tet, a->across});
    }
  });
  std::sort(faces.begin(), faces.end(), [](const InterfaceFace& a, const InterfaceFace& b) {
    return std::tie(a.labels, a.tet, a.across) < std::tie(b.labels, b.tet, b.across);
  });
  return faces;
}

std::vector<std::array<int32_t, 2>> interface_pairs(const std::vector<InterfaceFace>& faces) {
  std::vector<std::array<int32_t, 2>> pairs;
  for (const auto& face : faces) {
    if (pairs.empty() || pairs.back() != face.labels) pairs.push_back(face.labels);
  }
  return pairs;
}

}  // namespace labelmesh::volume_mesh
