// SPDX-License-Identifier: AGPL-3.0-or-later
// The Poisson options' checks that need no CGAL, so that job options can be
// validated where CGAL is not linked.
#include "core/surface/poisson_surface.h"
#include "core/util/text.h"

namespace labelmesh::surface {

absl::Status check_point_count(std::string_view field, uint64_t value) {
  if (value == 0 || value >= kMinPointBudget) return absl::OkStatus();
  return absl::InvalidArgumentError(
      cat(field, ": ", value, " is neither 0 (off) nor at least ", kMinPointBudget));
}

}  // namespace labelmesh::surface
