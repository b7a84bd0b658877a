// SPDX-License-Identifier: AGPL-3.0-or-later
// Vertex normals of a triangle surface, the input of Poisson reconstruction
// (paper §2.3: the average of the normals of the triangles around a vertex).
#pragma once

#include <vector>

#include "core/job/poisson_params.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/vec3.h"

namespace labelmesh::surface {

// One unit normal per point of `mesh`, pointing the way its triangles face.
// A point on no triangle, or whose normals cancel out, gets {0, 0, 0}.
std::vector<geometry::Vec3> vertex_normals(const TriangleMesh& mesh, NormalWeighting weighting);

}  // namespace labelmesh::surface
