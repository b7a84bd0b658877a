// SPDX-License-Identifier: AGPL-3.0-or-later
// The bounds of the Poisson options that need no CGAL to check, so that job
// options are checked where CGAL is not linked.
#pragma once

#include <cstdint>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh::surface {

// Clusters larger than this thin the points more than any use we measured.
inline constexpr uint32_t kMaxClusterSize = 64;
// A point budget below this thins even a small organ's surface.
inline constexpr uint64_t kMinPointBudget = 1000;

// A point count that 0 turns off (max_points, split_points): otherwise at
// least kMinPointBudget. INVALID_ARGUMENT names `field`.
absl::Status check_point_count(std::string_view field, uint64_t value);

}  // namespace labelmesh::surface
