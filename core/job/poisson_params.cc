// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/poisson_params.h"

#include "core/util/text.h"

namespace labelmesh::surface {

absl::Status check_point_count(std::string_view field, uint64_t value) {
  if (value == 0 || value >= kMinPointBudget) return absl::OkStatus();
  return absl::InvalidArgumentError(
      cat(field, ": ", value, " is neither 0 (off) nor at least ", kMinPointBudget));
}

}  // namespace labelmesh::surface
