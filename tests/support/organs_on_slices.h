// SPDX-License-Identifier: AGPL-3.0-or-later
// Organs on a short series of thick slices, as a DICOM SEG of a few slices
// holds them.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/volume/label_volume.h"
#include "support/label_grid.h"

namespace labelmesh::testing {

// Five organs cut by three 5 mm slices of 0.78 mm pixels: a large one, two
// touching it and each other, a round vessel beside them and a small one
// inside the large one. Each shrinks or grows from slice to slice as organs
// do across a short series.
inline volume::LabelVolume five_organs_on_three_slices() {
  constexpr int kPixels = 512;
  auto v = testing::label_grid({kPixels, kPixels, 3}, [](int i, int j, int k) -> uint8_t {
    const double x = (i - 256) * 0.78, y = (j - 256) * 0.78;
    const double grow = 1 + 0.12 * (k - 1);
    const auto inside = [&](double cx, double cy, double rx, double ry) {
      const double u = (x - cx) / (rx * grow), w = (y - cy) / (ry * grow);
      return u * u + w * w < 1;
    };
    if (inside(-40, 10, 18, 14)) return 5;  // inside the large organ
    if (inside(-50, 0, 80, 60)) return 1;
    if (inside(55, -10, 35, 25)) return 2;         // touches 1
    if (inside(50, 40, 30, 22)) return 3;          // touches 1 and 2
    if (std::hypot(x - 5, y + 70) < 12) return 4;  // a vessel, the same on every slice
    return 0;
  });
  v.geometry.spacing = {0.78, 0.78, 5};
  return v;
}

}  // namespace labelmesh::testing
