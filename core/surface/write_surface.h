// SPDX-License-Identifier: AGPL-3.0-or-later
// Surface mesh files: STL (binary), PLY (binary), OBJ, OFF and VTP.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <vtkSmartPointer.h>

#include "absl/status/status.h"
#include "core/surface/surface_format.h"
#include "core/surface/triangle_mesh.h"

class vtkPolyData;

namespace labelmesh::surface {

// The mesh as VTK polygons (points in mm, triangles as given).
vtkSmartPointer<vtkPolyData> to_polydata(const TriangleMesh& mesh);

// Writes `mesh` to `path`. VTK's writers do STL, PLY, OBJ and VTP; CGAL's does
// OFF. Errors: INTERNAL naming the file when it cannot be written.
absl::Status write_surface(const TriangleMesh& mesh, const std::string& path, SurfaceFormat format);

// OFF through CGAL's polygon-soup writer (write_off.cc keeps CGAL out of here).
absl::Status write_off(const TriangleMesh& mesh, const std::string& path);

}  // namespace labelmesh::surface
