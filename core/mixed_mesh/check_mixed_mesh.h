// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks and figures for mixed-element meshes: a well-formed mesh (check_mixed_mesh), a
// conforming one with a closed boundary (check_conformity), and element quality after §2.4.1 of
// "From segmented medical images to surface and volume meshes"
// (../shared/reference/segmented-images-to-meshes.md) with the metrics of
// core/quality/element_quality.h (measure_mixed_mesh).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "core/mixed_mesh/mixed_mesh.h"
#include "core/quality/element_quality.h"

namespace labelmesh::mixed_mesh {

// INVALID_ARGUMENT when the per-cell vectors (types, cells, labels) differ in size, a cell has
// an unknown type, names a point that does not exist, or names one point twice; OK otherwise.
absl::Status check_mixed_mesh(const MixedMesh& mesh);

// How the cells of a mesh fit together. Faces are the quads and triangles of local_faces
// (core/mixed_mesh/mixed_faces.h), matched by their point sets.
struct Conformity {
  // Point sets shared by exactly two cells whose windings are opposite.
  size_t interior_faces = 0;
  // Faces of one cell that match no other face: the mesh's outer surface.
  size_t boundary_faces = 0;
  // Faces that do not fit: a point set shared by more than two cells, two faces over the same
  // points with the same (or a twisted) winding, and a boundary quad against boundary triangles
  // over three of its corners (the quad and each such triangle count). None of these counts as a
  // boundary face.
  size_t nonconforming_faces = 0;
  // Points whose coordinates exactly equal those of another point, each group counted once
  // less than its size.
  size_t duplicate_points = 0;
  // Edges of boundary faces used by other than exactly two boundary faces: 0 on a closed,
  // manifold boundary.
  size_t open_boundary_edges = 0;

  bool ok() const {
    return nonconforming_faces == 0 && duplicate_points == 0 && open_boundary_edges == 0;
  }
};

// Matches every cell face against the others, and the points against each other.
// Precondition: check_mixed_mesh(mesh) is OK.
Conformity check_conformity(const MixedMesh& mesh);

// Signed volume of cell `cell`, in mm³: positive for a valid cell in VTK's ordering. It is the
// volume bounded by the cell's faces, with quads as bilinear patches, by the divergence theorem
// V = 1/3 ∮ x·n dA, exact for these faces (2x2 Gauss points per quad). For hexahedra and wedges
// it equals the integral of the isoparametric Jacobian; for pyramids, whose isoparametric map
// degenerates at the apex, it is the volume of the cone over the bilinear base. No tetrahedral
// split, so no choice of diagonals. Precondition: check_mixed_mesh(mesh) is OK.
double cell_signed_volume(const MixedMesh& mesh, size_t cell);

// Element quality of a mixed mesh (§2.4.1), per cell and summed up.
struct MixedQuality {
  // Per cell, in mesh order. Hexahedra, wedges, pyramids: their Jacobian ratio JR_e. A
  // tetrahedron's Jacobian is constant, so its ratio is 1 when its volume is positive, -1
  // otherwise.
  std::vector<double> jacobian_ratio;
  // Per cell, in mesh order: the figure Table 1 categorises. Tetrahedra: Q = tetra_quality;
  // the other cells: their jacobian_ratio.
  std::vector<double> quality;

  size_t hexahedra = 0;
  size_t wedges = 0;
  size_t pyramids = 0;
  size_t tetrahedra = 0;

  // Over all cells; +∞ and 0 for an empty mesh.
  double jacobian_ratio_min = std::numeric_limits<double>::infinity();
  double jacobian_ratio_mean = 0.0;
  // Smallest quality::pyramid_signed_aspect_ratio over the pyramids; empty when there are none.
  std::optional<double> pyramid_aspect_ratio_min;
  // Smallest quality::hexahedron_scaled_jacobian over the hexahedra; empty when there are none.
  std::optional<double> scaled_jacobian_min;
  // Tetrahedra only: Q (min, mean) and the dihedral range in degrees.
  quality::QualitySummary tetra_summary;
  // `quality` over all cells: min, mean and the Table 1 categories.
  quality::QualitySummary cell_summary;
  // Cells with a corner Jacobian ≤ 0 (tetrahedra: volume ≤ 0): inverted or flat. Not the same
  // as cell_summary.invalid, Table 1's category q ≤ 0.001.
  size_t invalid = 0;
  // Sum of the cells' signed volumes (see cell_signed_volume), in mm³.
  double volume_mm3 = 0.0;
};

// Measures every cell. Precondition: check_mixed_mesh(mesh) is OK.
MixedQuality measure_mixed_mesh(const MixedMesh& mesh);

}  // namespace labelmesh::mixed_mesh
