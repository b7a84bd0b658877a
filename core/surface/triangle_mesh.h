// SPDX-License-Identifier: AGPL-3.0-or-later
// A triangle surface in patient space: shared vertices, counter-clockwise
// triangles seen from outside (normals point out of the material).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace labelmesh::surface {

struct TriangleMesh {
  // LPS, mm.
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<uint32_t, 3>> triangles;

  // Reverses every triangle's winding, turning normals inside out.
  void flip_orientation();

  // Adds the points and triangles of `other` (a separate piece) to this mesh.
  void append(const TriangleMesh& other);
};

}  // namespace labelmesh::surface
