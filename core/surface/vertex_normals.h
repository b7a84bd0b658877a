// SPDX-License-Identifier: AGPL-3.0-or-later
// Vertex normals of a triangle surface, the input of Poisson reconstruction
// (paper §2.3: the average of the normals of the triangles around a vertex).
#pragma once

#include <vector>

#include "core/surface/triangle_mesh.h"
#include "core/util/vec3.h"

namespace labelmesh::surface {

enum class NormalWeighting {
  // Mean of the unit normals of incident triangles (the paper's choice, and
  // the default): on Marching Cubes surfaces, whose triangles come in a few
  // shapes and sizes, it follows the staircase's overall slope best.
  kUniform,
  // Sum of area-weighted normals: large triangles count more.
  kArea,
};

// One unit normal per point of `mesh`, pointing the way its triangles face.
// A point on no triangle, or whose normals cancel out, gets {0, 0, 0}.
std::vector<geometry::Vec3> vertex_normals(const TriangleMesh& mesh, NormalWeighting weighting);

}  // namespace labelmesh::surface
