// SPDX-License-Identifier: AGPL-3.0-or-later
// Which of the surface net's sheets pass through one voxel cube. Each edge
// of the cube joining two different labels carries a quad of the interface
// between them. Interfaces that share a label other than the outside pass
// into one another through the cube (that label's surface is one piece
// there) and share its point. Where two labels lie a voxel apart with
// outside between them, their interfaces with the outside share nothing
// else: each is given a point of its own, so the two surfaces can part.
#pragma once

#include <array>
#include <cstdint>

namespace labelmesh::conforming {

struct CubeSheets {
  // The distinct label pairs on the cube's edges (lower label first), and
  // the sheet each belongs to, numbered from 0 in order of first pair.
  std::array<std::array<int32_t, 2>, 12> pairs{};
  std::array<uint8_t, 12> sheet{};
  int pair_count = 0;
  int sheet_count = 0;
  // Per sheet, the distinct labels on its pairs: 2 on a plain sheet, 3 or
  // more where sheets meet.
  std::array<uint8_t, 12> labels{};

  // The sheet of the pair (a, b), in either order; -1 when no edge joins them.
  int sheet_of(int32_t a, int32_t b) const;
};

// The sheets through the cube whose corners hold `corner` (corner k at
// offsets k & 1, (k >> 1) & 1, k >> 2 along the three axes).
CubeSheets cube_sheets(const std::array<int32_t, 8>& corner);

}  // namespace labelmesh::conforming
