// SPDX-License-Identifier: AGPL-3.0-or-later
// Mixed-element mesh files for viewers and finite-element solvers: VTK XML unstructured grid,
// Gmsh MSH 2.2, Medit and Abaqus/CalculiX input. The names, frame and conventions are those of
// the tetrahedral writers (core/volume_mesh/write_volume_mesh.h).
#pragma once

#include <string>

#include "absl/status/status.h"
#include "core/job/volume_format.h"
#include "core/mixed_mesh/check_mixed_mesh.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/volume_mesh/write_volume_mesh.h"

namespace labelmesh::mixed_mesh {

// Writes `mesh` to `path`. Coordinates are written in mm, in full precision, in `info.frame`;
// labels are named by volume_mesh::label_group_name. Cells keep VTK's node ordering (MixedMesh)
// where the format shares it, and are reordered where it does not, so that no element is
// inverted: wedges go to Gmsh, Medit and Abaqus with their bottom triangle reversed
// (0,2,1,3,5,4), since those formats wind it counter-clockwise seen from the top triangle and
// VTK winds it clockwise. `quality.jacobian_ratio` and `quality.quality` are each empty or
// hold one value per cell (see measure_mixed_mesh); they go to the formats with element data.
//
// - kVtu: vtkUnstructuredGrid with VTK_HEXAHEDRON, VTK_PYRAMID, VTK_WEDGE and VTK_TETRA cells,
//   appended zlib-compressed data; cell arrays "label" (int32), "element_type" (int32, the VTK
//   cell type), "jacobian_ratio" and "quality" (float64, when given); numeric field data as the
//   tetrahedral VTU: one array per label, named by its group name and holding the label, and
//   "SPACE=LPS" (or "SPACE=RAS") holding 1.
// - kMsh: Gmsh MSH 2.2 ASCII, element types 5 (hexahedron), 6 (prism), 7 (pyramid) and 4
//   (tetrahedron), element number = cell index + 1; one 3D physical group per label, tag =
//   label, named by its group name; each element's physical and elementary tag is its label.
//   No element data, which meshio cannot read over several cell types (the VTU has it).
//   Labels must be positive.
// - kMedit: MeshVersionFormatted 2, comments naming the frame and each label; Hexahedra,
//   Prisms, Pyramids and Tetrahedra with ref = label, and the Triangles and Quadrilaterals of
//   each label's boundary (see label_boundary_faces) with ref = label, wound out of the label's
//   region; vertices have ref 0.
// - kAbaqus: Abaqus/CalculiX .inp, 1-based, element id = cell index + 1. C3D8, C3D6 and C3D4
//   elements, one *ELEMENT block per type; pyramids as C3D8 with the apex repeated
//   (1,2,3,4,5,5,5,5), which the file says in a comment. ELSET=<G> lists each label's elements
//   and NSET=<G>_BOUNDARY the points of its boundary, where <G> is the upper-case group name
//   (LABEL_5_LIVER). Labels must be positive.
// - kTetgen: not written: TetGen's .node/.ele pair holds tetrahedra only.
// - kXdmf: not written: labelmesh writes XDMF for tetrahedral meshes only.
//
// Errors: INVALID_ARGUMENT naming the file when the mesh is malformed (see check_mixed_mesh),
// a quality vector has the wrong size, a label is not positive where it must be, or the format
// is kTetgen or kXdmf; INTERNAL naming the file when it cannot be written.
absl::Status write_mixed_mesh(const MixedMesh& mesh, const MixedQuality& quality,
                              const std::string& path, volume_mesh::VolumeFormat format,
                              const volume_mesh::VolumeFileInfo& info = {});

}  // namespace labelmesh::mixed_mesh
