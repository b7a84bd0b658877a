// SPDX-License-Identifier: AGPL-3.0-or-later
// Volume-element quality metrics used by every volume mesher: the tetrahedron quality
// Q = 1/A_gamma, the Jacobian ratio of hexahedra, wedges and pyramids, a signed aspect ratio for
// pyramids, and the quality categories of Table 1. Reference for the whole file: §2.4.1 of "From
// segmented medical images to surface and volume meshes"
// (../shared/reference/segmented-images-to-meshes.md).
//
// Node orderings are VTK's (VTK_TETRA, VTK_HEXAHEDRON, VTK_WEDGE, VTK_PYRAMID), so cells can be
// written to .vtu without reordering. Lengths are in the input unit (mm in labelmesh); qualities
// and ratios are dimensionless. Every function is pure and thread-safe, and none throws.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>

#include "core/util/vec3.h"

namespace labelmesh::quality {

using Point = geometry::Vec3;
// VTK_TETRA: the right-hand normal of triangle 0,1,2 points towards node 3.
using Tet = std::array<Point, 4>;
// VTK_HEXAHEDRON: 0-3 the bottom face counter-clockwise seen from above, 4-7 above 0-3.
using Hex = std::array<Point, 8>;
// VTK_WEDGE: 0,1,2 the bottom triangle, 3,4,5 above them. VTK's bottom triangle winds CLOCKWISE
// seen from the top face: its right-hand normal points out of the element (vtkWedge.h).
using Wedge = std::array<Point, 6>;
// VTK_PYRAMID: 0-3 the base, whose right-hand normal points towards the apex 4.
using Pyramid = std::array<Point, 5>;

// Signed volume of a tetrahedron, in length³ (mm³); positive for VTK ordering, negative when
// inverted. §2.4.1 (the V of A_gamma).
double tetra_signed_volume(const Tet& p);

// Tetrahedron quality Q = 1/A_gamma = 6√2·V / l_rms³, dimensionless, where V is the signed volume
// and l_rms = sqrt(Σ l_i² / 6) over the six edges. 1 for a regular tetrahedron, ~0 for slivers and
// needles, negative when inverted; 0 when all edges have zero length. §2.4.1, A_gamma formula.
double tetra_quality(const Tet& p);

// Smallest (first) and largest (second) of the six interior dihedral angles, in degrees, in
// [0, 180]. Unoriented: an inverted tetrahedron has the angles of its mirror image. A regular
// tetrahedron gives acos(1/3) ≈ 70.53° for both. §2.4.1 (sliver detection).
std::pair<double, double> tetra_dihedral_range_deg(const Tet& p);

// Jacobian ratio JR_e = J_min / J_max of a set of corner Jacobians (any unit), dimensionless, in
// (-∞, 1]. When J_max ≤ 0 (every corner inverted or flat) there is no positive scale to
// normalise by and the result is -1; an empty span also gives -1. §2.4.1, JR_e definition.
double jacobian_ratio(std::span<const double> corner_jacobians);

// Corner Jacobians of a hexahedron, in length³, indexed by node: the determinant of the
// trilinear map's Jacobian on the parametric cube [0,1]³ at that node, which is the triple product
// of the three edges leaving the node taken right-handedly. All positive for a valid hexahedron;
// 1 at every corner of the unit cube. §2.4.1, |J(ξ)| at the nodes.
std::array<double, 8> hexahedron_corner_jacobians(const Hex& p);

// Per corner of a hexahedron, indexed by node: its Jacobian (as hexahedron_corner_jacobians)
// and the product of the lengths of the three edges leaving it, length³.
struct HexCorners {
  std::array<double, 8> jacobian;
  std::array<double, 8> edge_lengths;
};
HexCorners hexahedron_corners(const Hex& p);

// Jacobian ratio of a hexahedron, dimensionless (see jacobian_ratio). 1 for any parallelepiped,
// negative when any corner is inverted. §2.4.1, JR_e.
double hexahedron_jacobian_ratio(const Hex& p);

// Scaled Jacobian of a hexahedron, dimensionless, in [-1, 1]: the smallest corner Jacobian
// divided by the product of the lengths of its three edges (Verdict's definition). Unlike the
// Jacobian ratio it falls with shear: a parallelepiped with a 30° angle scores 0.5. 1 for a
// cube; 0 when an edge has zero length.
double hexahedron_scaled_jacobian(const Hex& p);

// Corner Jacobians of a wedge, in length³, indexed by node: the triple product of the two
// triangle edges and the vertical edge leaving the node, ordered so that a valid wedge in VTK's
// ordering is positive. This is the NEGATED determinant of VTK's own isoparametric map at the node:
// VTK's clockwise bottom triangle makes that map left-handed on valid wedges. §2.4.1, |J(ξ)|.
std::array<double, 6> wedge_corner_jacobians(const Wedge& p);

// Jacobian ratio of a wedge, dimensionless (see jacobian_ratio). 1 for any right or oblique
// prism with parallel, congruent triangles; negative when inverted. §2.4.1, JR_e.
double wedge_jacobian_ratio(const Wedge& p);

// Corner Jacobians at the 4 base nodes of a pyramid, in length³: triple product of the two base
// edges leaving the node (next, then previous node of the base) and the edge to the apex; equal to
// the determinant of VTK's isoparametric map there. The apex is left out because that map
// degenerates at the apex (its Jacobian is singular there for every pyramid). Corner i is also
// 6 × the signed volume of the tetrahedron (i, i+1, i-1, apex). §2.4.1, |J(ξ)|.
std::array<double, 4> pyramid_corner_jacobians(const Pyramid& p);

// Jacobian ratio of a pyramid over its 4 base corners, dimensionless (see jacobian_ratio). 1 for
// any pyramid with a parallelogram base and its apex on the valid side, however skewed; negative
// when a corner is inverted. §2.4.1, JR_e.
double pyramid_jacobian_ratio(const Pyramid& p);

// Signed, normalised aspect ratio of a pyramid, dimensionless; §2.4.1, the pyramid AR after the
// paper's ref. [16]. Definition: split the pyramid at each base corner i into the tetrahedron
// (i, i+1, i-1, apex), take the smallest tetra_quality of the four and divide it by the same figure
// for the ideal pyramid (square base, all 8 edges equal), (6/7)^(3/2). The ideal pyramid scores 1;
// it is not an upper bound: taller pyramids reach ≈1.06. Any inverted corner makes it negative,
// and unlike the JR it falls towards 0 for skewed or flattened pyramids.
double pyramid_signed_aspect_ratio(const Pyramid& p);

// The quality categories of Table 1, for the JR of hexahedra, wedges and pyramids and for Q of
// tetrahedra (§2.4.1).
enum class QualityCategory {
  kInvalid,       // q ≤ 0.001: unusable for FEA (ANSYS).
  kVeryBad,       // 0.001 < q ≤ 1/30: usable, inaccurate solution.
  kQuestionable,  // 1/30 < q ≤ 0.2: Verdict's questionable range.
  kGood,          // q > 0.2.
};

// Category of a dimensionless quality q per Table 1; NaN counts as invalid. §2.4.1, Table 1.
QualityCategory categorize(double q);

// Running summary of element qualities (Q, JR or AR, dimensionless) and tetrahedron dihedral
// angles (degrees), as reported in Table 3 (§3). Fill with add() / add_dihedral_range(); combine
// per-thread summaries with merge().
struct QualitySummary {
  // Smallest quality added; +∞ while count == 0.
  double min = std::numeric_limits<double>::infinity();
  // Arithmetic mean of the qualities added; 0 while count == 0.
  double mean = 0.0;
  std::int64_t count = 0;
  // Counts per Table 1 category; they sum to count.
  std::int64_t invalid = 0;
  std::int64_t very_bad = 0;
  std::int64_t questionable = 0;
  std::int64_t good = 0;
  // Extreme dihedral angles seen, in degrees; +∞ / -∞ while none was added.
  double min_dihedral_deg = std::numeric_limits<double>::infinity();
  double max_dihedral_deg = -std::numeric_limits<double>::infinity();

  // Adds one element's quality q (dimensionless).
  void add(double q);
  // Adds one tetrahedron's dihedral range (degrees), as returned by tetra_dihedral_range_deg.
  void add_dihedral_range(std::pair<double, double> range_deg);
  // Folds another summary into this one, as if its elements had been added here.
  void merge(const QualitySummary& other);
};

}  // namespace labelmesh::quality
