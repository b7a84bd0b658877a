// SPDX-License-Identifier: AGPL-3.0-or-later
// How large a conforming mesh's interfaces may grow before its grid is
// coarsened (conforming/coarsen_labels.h), apart from the code that does it.
#pragma once

#include <cstdint>

namespace labelmesh::conforming {

// Voxel faces between labels: about 1 GiB at most for a whole conforming
// run (a 40-label brain resampled to 200,000 such faces peaks near
// 0.8 GiB).
inline constexpr uint64_t kDefaultMaxInterfaceFaces = 200'000;

}  // namespace labelmesh::conforming
