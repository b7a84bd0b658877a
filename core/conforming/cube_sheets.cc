// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/cube_sheets.h"

#include <algorithm>
#include <numeric>

#include "core/conforming/interface_surface.h"

namespace labelmesh::conforming {

int CubeSheets::sheet_of(int32_t a, int32_t b) const {
  if (a > b) std::swap(a, b);
  for (int k = 0; k < pair_count; ++k)
    if (pairs[k][0] == a && pairs[k][1] == b) return sheet[k];
  return -1;
}

CubeSheets cube_sheets(const std::array<int32_t, 8>& corner) {
  CubeSheets s;
  for (int k = 0; k < 8; ++k) {
    for (const int bit : {1, 2, 4}) {
      if ((k & bit) != 0 || corner[k] == corner[k | bit]) continue;
      const std::array<int32_t, 2> pair{std::min(corner[k], corner[k | bit]),
                                        std::max(corner[k], corner[k | bit])};
      if (std::find(s.pairs.begin(), s.pairs.begin() + s.pair_count, pair) ==
          s.pairs.begin() + s.pair_count)
        s.pairs[s.pair_count++] = pair;
    }
  }
  // Pairs joined where they share a label other than the outside: that
  // label's surface passes from one to the other through the cube.
  std::array<int, 12> root{};
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](int k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  for (int p = 0; p < s.pair_count; ++p) {
    for (int q = p + 1; q < s.pair_count; ++q) {
      bool shared = false;
      for (const int32_t label : s.pairs[p])
        shared =
            shared || (label != kOutside && (label == s.pairs[q][0] || label == s.pairs[q][1]));
      if (shared) root[find(p)] = find(q);
    }
  }
  std::array<int, 12> number;
  number.fill(-1);
  for (int p = 0; p < s.pair_count; ++p) {
    const int r = find(p);
    if (number[r] < 0) number[r] = s.sheet_count++;
    s.sheet[p] = static_cast<uint8_t>(number[r]);
  }
  for (int g = 0; g < s.sheet_count; ++g) {
    std::array<int32_t, 8> seen{};
    int count = 0;
    for (int p = 0; p < s.pair_count; ++p) {
      if (s.sheet[p] != g) continue;
      for (const int32_t label : s.pairs[p])
        if (std::find(seen.begin(), seen.begin() + count, label) == seen.begin() + count)
          seen[count++] = label;
    }
    s.labels[g] = static_cast<uint8_t>(count);
  }
  return s;
}

}  // namespace labelmesh::conforming
