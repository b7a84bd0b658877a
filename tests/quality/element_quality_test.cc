// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/quality/element_quality.h"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include "support/perturbed_cell.h"

namespace labelmesh::quality {
namespace {

const double kSqrt3 = std::sqrt(3.0);

// Edge 1, base counter-clockwise seen from above, apex above: positive in VTK ordering.
Tet regular_tet() {
  return {{{0, 0, 0}, {1, 0, 0}, {0.5, kSqrt3 / 2, 0}, {0.5, kSqrt3 / 6, std::sqrt(2.0 / 3.0)}}};
}

Hex unit_cube() {
  return {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
}

// VTK's wedge: the bottom triangle winds clockwise seen from the top (normal -z), top above it.
Wedge right_prism_right_triangle() {
  return {{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 2}, {0, 1, 2}, {1, 0, 2}}};
}

Wedge right_prism_equilateral() {
  return {{{0, 0, 0}, {0.5, kSqrt3 / 2, 0}, {1, 0, 0}, {0, 0, 1}, {0.5, kSqrt3 / 2, 1}, {1, 0, 1}}};
}

// Unit square base, all 8 edges of length 1.
Pyramid ideal_pyramid() {
  return {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, std::sqrt(0.5)}}};
}

template <typename Cell>
Cell mirrored_z(Cell cell) {
  for (Point& point : cell) point[2] = -point[2];
  return cell;
}

// x ↦ s·R·x + t for a random rotation R, scale s and translation t.
class RandomSimilarity {
 public:
  explicit RandomSimilarity(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> log_scale(-3.0, 3.0);
    std::uniform_real_distribution<double> offset(-1e3, 1e3);
    // Rotation from a random unit quaternion.
    double q[4];
    double length = 0.0;
    for (double& c : q) {
      c = normal(rng);
      length += c * c;
    }
    length = std::sqrt(length);
    for (double& c : q) c /= length;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    rotation_ = {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                  {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                  {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
    scale_ = std::pow(10.0, log_scale(rng));
    translation_ = {offset(rng), offset(rng), offset(rng)};
  }

  template <typename Cell>
  Cell operator()(Cell cell) const {
    for (Point& point : cell) {
      Point moved{};
      for (int i = 0; i < 3; ++i) {
        moved[i] = translation_[i] + scale_ * geometry::dot(rotation_[i], point);
      }
      point = moved;
    }
    return cell;
  }

 private:
  std::array<Point, 3> rotation_{};
  double scale_ = 1.0;
  Point translation_{};
};

void expect_relatively_near(double expected, double actual, double tolerance) {
  EXPECT_NEAR(expected, actual, tolerance * std::max(1.0, std::abs(expected)));
}

TEST(TetraTest, RegularTetScoresOne) {
  const Tet tet = regular_tet();
  EXPECT_NEAR(tetra_quality(tet), 1.0, 1e-12);
  EXPECT_NEAR(tetra_signed_volume(tet), 1.0 / (6.0 * std::numbers::sqrt2), 1e-15);
  const auto [lo, hi] = tetra_dihedral_range_deg(tet);
  const double expected = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(expected, 70.528779, 1e-6);
  EXPECT_NEAR(lo, expected, 1e-10);
  EXPECT_NEAR(hi, expected, 1e-10);
}

TEST(TetraTest, CornerOfCubeHasKnownVolumeAndRightAngles) {
  const Tet tet = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  EXPECT_DOUBLE_EQ(tetra_signed_volume(tet), 1.0 / 6.0);
  const auto [lo, hi] = tetra_dihedral_range_deg(tet);
  EXPECT_NEAR(lo, std::acos(1.0 / kSqrt3) * 180.0 / std::numbers::pi, 1e-10);  // the slanted face
  EXPECT_NEAR(hi, 90.0, 1e-10);
}

TEST(TetraTest, InvertedTetIsNegative) {
  Tet tet = regular_tet();
  std::swap(tet[1], tet[2]);
  EXPECT_NEAR(tetra_quality(tet), -1.0, 1e-12);
  EXPECT_LT(tetra_signed_volume(tet), 0.0);
  EXPECT_NEAR(tetra_quality(mirrored_z(regular_tet())), -1.0, 1e-12);
  // Dihedral angles are unoriented: the mirror image has the same ones.
  const auto [lo, hi] = tetra_dihedral_range_deg(tet);
  EXPECT_NEAR(lo, 70.528779, 1e-6);
  EXPECT_NEAR(hi, 70.528779, 1e-6);
}

TEST(TetraTest, SliverScoresNearZero) {
  // Four points near the corners of the unit square; the diagonals 0-2 and 1-3 nearly cross.
  const double lift = 0.01;
  const Tet sliver = {{{0, 0, 0}, {1, 0, lift}, {1, 1, 0}, {0, 1, lift}}};
  const double q = tetra_quality(sliver);
  EXPECT_GT(q, 0.0);
  EXPECT_LT(q, 0.05);
  const auto [lo, hi] = tetra_dihedral_range_deg(sliver);
  EXPECT_LT(lo, 5.0);
  EXPECT_GT(hi, 175.0);
  EXPECT_EQ(categorize(q), QualityCategory::kVeryBad);
}

TEST(TetraTest, DegenerateTetScoresZero) {
  const Tet point = {{{2, 3, 4}, {2, 3, 4}, {2, 3, 4}, {2, 3, 4}}};
  EXPECT_EQ(tetra_quality(point), 0.0);
  const Tet flat = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}};
  EXPECT_EQ(tetra_quality(flat), 0.0);
  EXPECT_EQ(categorize(tetra_quality(flat)), QualityCategory::kInvalid);
}

TEST(HexahedronTest, UnitCubeHasUnitCornerJacobians) {
  for (double j : hexahedron_corner_jacobians(unit_cube())) EXPECT_DOUBLE_EQ(j, 1.0);
  EXPECT_DOUBLE_EQ(hexahedron_jacobian_ratio(unit_cube()), 1.0);
}

TEST(HexahedronTest, ParallelepipedScoresOne) {
  Hex hex = unit_cube();
  for (Point& point : hex) {
    point = {2 * point[0] + 0.5 * point[1] + 0.3 * point[2], point[1] + 0.4 * point[2],
             3 * point[2]};
  }
  EXPECT_NEAR(hexahedron_jacobian_ratio(hex), 1.0, 1e-12);
}

TEST(HexahedronTest, InvertedHexIsNegative) {
  EXPECT_DOUBLE_EQ(hexahedron_jacobian_ratio(mirrored_z(unit_cube())), -1.0);
  Hex swapped = unit_cube();  // top and bottom faces exchanged
  for (int i = 0; i < 4; ++i) std::swap(swapped[i], swapped[i + 4]);
  EXPECT_LT(hexahedron_jacobian_ratio(swapped), 0.0);
  Hex dented = unit_cube();  // one top corner pushed below the bottom face
  dented[6][2] = -0.5;
  EXPECT_LT(hexahedron_jacobian_ratio(dented), 0.0);
}

TEST(HexahedronTest, CollapsedCornerIsInvalid) {
  // Node 6 moved onto the plane of its three neighbours 2, 5 and 7: its corner Jacobian vanishes.
  Hex hex = unit_cube();
  hex[6] = {2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
  EXPECT_NEAR(hexahedron_corner_jacobians(hex)[6], 0.0, 1e-15);
  const double jr = hexahedron_jacobian_ratio(hex);
  EXPECT_NEAR(jr, 0.0, 1e-15);
  EXPECT_EQ(categorize(jr), QualityCategory::kInvalid);
}

TEST(WedgeTest, RightPrismsScoreOne) {
  for (const Wedge& wedge : {right_prism_right_triangle(), right_prism_equilateral()}) {
    for (double j : wedge_corner_jacobians(wedge)) EXPECT_GT(j, 0.0);
    EXPECT_NEAR(wedge_jacobian_ratio(wedge), 1.0, 1e-12);
  }
  // Right triangle with unit legs, height 2: each corner's triple product is 1·1·2.
  for (double j : wedge_corner_jacobians(right_prism_right_triangle())) EXPECT_DOUBLE_EQ(j, 2.0);
}

TEST(WedgeTest, ObliquePrismScoresOne) {
  Wedge wedge = right_prism_equilateral();
  for (int i = 3; i < 6; ++i) wedge[i] = geometry::add(wedge[i], {0.4, -0.3, 0.5});
  EXPECT_NEAR(wedge_jacobian_ratio(wedge), 1.0, 1e-12);
}

TEST(WedgeTest, InvertedWedgeIsNegative) {
  // Counter-clockwise bottom (the tetrahedron's convention, not VTK's wedge's).
  Wedge swapped = right_prism_equilateral();
  std::swap(swapped[1], swapped[2]);
  std::swap(swapped[4], swapped[5]);
  EXPECT_DOUBLE_EQ(wedge_jacobian_ratio(swapped), -1.0);
  EXPECT_DOUBLE_EQ(wedge_jacobian_ratio(mirrored_z(right_prism_equilateral())), -1.0);
  Wedge pinched = right_prism_right_triangle();  // one top node pushed below the bottom
  pinched[5][2] = -1.0;
  EXPECT_LT(wedge_jacobian_ratio(pinched), 0.0);
}

TEST(PyramidTest, SquarePyramidsHaveUnitJacobianRatio) {
  EXPECT_NEAR(pyramid_jacobian_ratio(ideal_pyramid()), 1.0, 1e-12);
  for (double j : pyramid_corner_jacobians(ideal_pyramid())) EXPECT_NEAR(j, std::sqrt(0.5), 1e-15);
  Pyramid flat = ideal_pyramid();
  flat[4][2] = 0.05;
  EXPECT_NEAR(pyramid_jacobian_ratio(flat), 1.0, 1e-12);
}

TEST(PyramidTest, IdealPyramidHasUnitAspect) {
  EXPECT_NEAR(pyramid_signed_aspect_ratio(ideal_pyramid()), 1.0, 1e-12);
}

TEST(PyramidTest, AspectSeesSkewThatJacobianRatioMisses) {
  Pyramid skewed = ideal_pyramid();
  skewed[4] = {4.0, 0.5, 0.3};  // apex far outside the base, still above it
  EXPECT_NEAR(pyramid_jacobian_ratio(skewed), 1.0, 1e-12);
  const double aspect = pyramid_signed_aspect_ratio(skewed);
  EXPECT_GT(aspect, 0.0);
  EXPECT_LT(aspect, 0.2);
  Pyramid squashed = ideal_pyramid();
  squashed[4][2] = 0.01;
  EXPECT_EQ(categorize(pyramid_signed_aspect_ratio(squashed)), QualityCategory::kVeryBad);
}

TEST(PyramidTest, InvertedPyramidIsNegative) {
  Pyramid below = ideal_pyramid();  // apex mirrored through the base
  below[4][2] = -below[4][2];
  EXPECT_DOUBLE_EQ(pyramid_jacobian_ratio(below), -1.0);
  EXPECT_LT(pyramid_signed_aspect_ratio(below), 0.0);
  Pyramid dart = ideal_pyramid();  // base corner 2 pushed past the diagonal 1-3: a reflex corner
  dart[2] = {0.2, 0.2, 0.0};
  EXPECT_LT(pyramid_jacobian_ratio(dart), 0.0);
  EXPECT_LT(pyramid_signed_aspect_ratio(dart), 0.0);
}

TEST(JacobianRatioTest, FullyInvertedOrFlatGivesMinusOne) {
  const std::vector<double> negative = {-1.0, -2.0, -0.5};
  EXPECT_EQ(jacobian_ratio(negative), -1.0);
  const std::vector<double> zero = {0.0, 0.0};
  EXPECT_EQ(jacobian_ratio(zero), -1.0);
  EXPECT_EQ(jacobian_ratio({}), -1.0);
  const std::vector<double> mixed = {2.0, -1.0, 4.0};
  EXPECT_DOUBLE_EQ(jacobian_ratio(mixed), -0.25);
}

TEST(CategoryTest, Table1Boundaries) {
  EXPECT_EQ(categorize(-5.0), QualityCategory::kInvalid);
  EXPECT_EQ(categorize(0.0), QualityCategory::kInvalid);
  EXPECT_EQ(categorize(0.001), QualityCategory::kInvalid);
  EXPECT_EQ(categorize(0.0011), QualityCategory::kVeryBad);
  EXPECT_EQ(categorize(1.0 / 30.0), QualityCategory::kVeryBad);
  EXPECT_EQ(categorize(0.034), QualityCategory::kQuestionable);
  EXPECT_EQ(categorize(0.2), QualityCategory::kQuestionable);
  EXPECT_EQ(categorize(0.2001), QualityCategory::kGood);
  EXPECT_EQ(categorize(1.0), QualityCategory::kGood);
  EXPECT_EQ(categorize(std::nan("")), QualityCategory::kInvalid);
}

TEST(QualitySummaryTest, CountsMinMeanAndDihedrals) {
  QualitySummary summary;
  EXPECT_EQ(summary.count, 0);
  for (double q : {-0.5, 0.0005, 0.01, 0.1, 0.9, 1.0}) summary.add(q);
  EXPECT_EQ(summary.count, 6);
  EXPECT_DOUBLE_EQ(summary.min, -0.5);
  EXPECT_NEAR(summary.mean, (-0.5 + 0.0005 + 0.01 + 0.1 + 0.9 + 1.0) / 6.0, 1e-15);
  EXPECT_EQ(summary.invalid, 2);
  EXPECT_EQ(summary.very_bad, 1);
  EXPECT_EQ(summary.questionable, 1);
  EXPECT_EQ(summary.good, 2);
  summary.add_dihedral_range({30.0, 100.0});
  summary.add_dihedral_range(tetra_dihedral_range_deg(regular_tet()));
  EXPECT_DOUBLE_EQ(summary.min_dihedral_deg, 30.0);
  EXPECT_DOUBLE_EQ(summary.max_dihedral_deg, 100.0);
}

TEST(QualitySummaryTest, MergeEqualsAddingEverythingToOne) {
  const std::vector<double> first = {0.3, 0.02, 0.7};
  const std::vector<double> second = {-0.1, 0.5};
  QualitySummary all, a, b;
  for (double q : first) {
    all.add(q);
    a.add(q);
  }
  for (double q : second) {
    all.add(q);
    b.add(q);
  }
  a.add_dihedral_range({20.0, 120.0});
  b.add_dihedral_range({10.0, 90.0});
  QualitySummary empty;
  a.merge(empty);
  a.merge(b);
  EXPECT_EQ(a.count, all.count);
  EXPECT_DOUBLE_EQ(a.min, all.min);
  EXPECT_NEAR(a.mean, all.mean, 1e-15);
  EXPECT_EQ(a.invalid, all.invalid);
  EXPECT_EQ(a.very_bad, all.very_bad);
  EXPECT_EQ(a.questionable, all.questionable);
  EXPECT_EQ(a.good, all.good);
  EXPECT_DOUBLE_EQ(a.min_dihedral_deg, 10.0);
  EXPECT_DOUBLE_EQ(a.max_dihedral_deg, 120.0);
}

// Every figure is a ratio of like powers of length or an angle, so a similarity transform
// (rotation, uniform scale, translation) must leave it unchanged.
TEST(InvarianceTest, SimilarityTransformsLeaveQualityUnchanged) {
  std::mt19937 rng(20240611);
  constexpr double kTolerance = 1e-9;
  for (int trial = 0; trial < 100; ++trial) {
    const RandomSimilarity move(rng);

    const Tet tet = testing::perturbed(regular_tet(), rng, 0.25);
    expect_relatively_near(tetra_quality(tet), tetra_quality(move(tet)), kTolerance);
    const auto [lo, hi] = tetra_dihedral_range_deg(tet);
    const auto [moved_lo, moved_hi] = tetra_dihedral_range_deg(move(tet));
    expect_relatively_near(lo, moved_lo, kTolerance);
    expect_relatively_near(hi, moved_hi, kTolerance);

    const Hex hex = testing::perturbed(unit_cube(), rng, 0.3);
    expect_relatively_near(hexahedron_jacobian_ratio(hex), hexahedron_jacobian_ratio(move(hex)),
                           kTolerance);
    const Wedge wedge = testing::perturbed(right_prism_equilateral(), rng, 0.3);
    expect_relatively_near(wedge_jacobian_ratio(wedge), wedge_jacobian_ratio(move(wedge)),
                           kTolerance);
    const Pyramid pyramid = testing::perturbed(ideal_pyramid(), rng, 0.3);
    expect_relatively_near(pyramid_jacobian_ratio(pyramid), pyramid_jacobian_ratio(move(pyramid)),
                           kTolerance);
    expect_relatively_near(pyramid_signed_aspect_ratio(pyramid),
                           pyramid_signed_aspect_ratio(move(pyramid)), kTolerance);
  }
}

// Mildly perturbed cells stay valid: the sign conventions hold away from the ideal shapes too.
TEST(InvarianceTest, MildlyPerturbedCellsStayPositive) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    EXPECT_GT(tetra_quality(testing::perturbed(regular_tet(), rng, 0.1)), 0.0);
    EXPECT_GT(hexahedron_jacobian_ratio(testing::perturbed(unit_cube(), rng, 0.1)), 0.0);
    EXPECT_GT(wedge_jacobian_ratio(testing::perturbed(right_prism_equilateral(), rng, 0.1)), 0.0);
    const Pyramid pyramid = testing::perturbed(ideal_pyramid(), rng, 0.1);
    EXPECT_GT(pyramid_jacobian_ratio(pyramid), 0.0);
    EXPECT_GT(pyramid_signed_aspect_ratio(pyramid), 0.0);
  }
}

}  // namespace
}  // namespace labelmesh::quality
