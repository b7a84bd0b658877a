// SPDX-License-Identifier: AGPL-3.0-or-later
// Reading a pipeline run's results in tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>

#include "core/pipeline/mesh_result.h"

namespace labelmesh::testing {

// The surface delivered for `label`, or null when none is.
inline const SurfaceResult* output_of(const MeshResult& result, int32_t label) {
  for (const auto& s : result.surfaces)
    if (s.label == label && s.is_output) return &s;
  return nullptr;
}

// The surface delivered for `label`, expected to be the net within the voxel
// tolerance; null, with a failure, when none is delivered.
inline const SurfaceResult* net_within_tolerance(const MeshResult& result, int32_t label) {
  const SurfaceResult* s = output_of(result, label);
  EXPECT_NE(s, nullptr) << label;
  if (s == nullptr) return nullptr;
  EXPECT_EQ(s->stage, "net") << label;
  EXPECT_TRUE(s->fidelity->within_tolerance()) << label;
  return s;
}

}  // namespace labelmesh::testing
