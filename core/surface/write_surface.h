// SPDX-License-Identifier: AGPL-3.0-or-later
// Surface mesh files: STL (binary), PLY (binary), OBJ, OFF and VTP.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <vtkSmartPointer.h>

#include "absl/status/status.h"
#include "core/job/surface_format.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/coordinate_frame.h"

class vtkPolyData;

namespace labelmesh::surface {

// What a surface file says about itself besides its triangles.
struct SurfaceFileInfo {
  // The label the surface bounds and its name (may be empty).
  int32_t label = 0;
  std::string name;
  // Points are written in this frame, and the file says which, as 3D Slicer
  // does: "SPACE=LPS" in the STL header, a PLY or OBJ comment, VTP field data.
  CoordinateFrame frame = CoordinateFrame::kLps;
};

// The mesh as VTK polygons (points in mm, in `frame`; triangles as given).
vtkSmartPointer<vtkPolyData> to_polydata(const TriangleMesh& mesh,
                                         CoordinateFrame frame = CoordinateFrame::kLps);

// Writes `mesh` to `path`. VTK's writers do STL, PLY and VTP, CGAL's OFF, and
// obj_file.cc OBJ (with a group named after the label). VTP carries the
// label as "label" cell data and, as field data, "label", "name" and "SPACE".
// OFF has no place for the frame. Errors: INTERNAL naming the file when it
// cannot be written.
absl::Status write_surface(const TriangleMesh& mesh, const std::string& path, SurfaceFormat format,
                           const SurfaceFileInfo& info = {});

// Every label's surface in one VTK multiblock file (`path` ends in .vtm; the
// blocks go to VTK's directory of .vtp files beside it), one block per label
// named "label <N> <name>", so ParaView opens all organs at once.
absl::Status write_surface_scene(const std::vector<const TriangleMesh*>& meshes,
                                 const std::vector<SurfaceFileInfo>& infos,
                                 const std::string& path);

// OFF through CGAL's polygon-soup writer (write_off.cc keeps CGAL out of here).
absl::Status write_off(const TriangleMesh& mesh, const std::string& path);

// Wavefront OBJ: comments with the frame and the label, one group per label.
absl::Status write_obj(const TriangleMesh& mesh, const std::string& path,
                       const SurfaceFileInfo& info);

}  // namespace labelmesh::surface
