// SPDX-License-Identifier: AGPL-3.0-or-later
// How large a conforming mesh's interfaces may grow before its grid is
// coarsened (coarsen_labels.h), apart from the code that does it.
#pragma once

#include <cstdint>

namespace labelmesh::conforming {

// Voxel faces between labels: about 1 GiB at most for a whole conforming
// run.
inline constexpr uint64_t kDefaultMaxInterfaceFaces = 400'000;

}  // namespace labelmesh::conforming
