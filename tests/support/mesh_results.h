// SPDX-License-Identifier: AGPL-3.0-or-later
// Reading a pipeline run's results in tests.
#pragma once

#include <cstdint>

#include "core/pipeline/mesh_result.h"

namespace labelmesh::testing {

// The surface delivered for `label`, or null when none is.
inline const SurfaceResult* output_of(const MeshResult& result, int32_t label) {
  for (const auto& s : result.surfaces)
    if (s.label == label && s.is_output) return &s;
  return nullptr;
}

}  // namespace labelmesh::testing
