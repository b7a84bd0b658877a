// SPDX-License-Identifier: AGPL-3.0-or-later
// Each label's voxel volume, and the identity direction, for tests that
// compare meshes with the voxels they came from.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh::testing {

constexpr std::array<double, 9> kIdentityDirection{1, 0, 0, 0, 1, 0, 0, 0, 1};

// Label -> its voxels' volume, mm^3.
inline std::map<int32_t, double> label_volumes(const volume::LabelVolume& volume) {
  std::map<int32_t, double> volumes;
  for (const auto& label : volume::compute_label_statistics(volume).labels)
    volumes[label.label] = static_cast<double>(label.voxels) * volume.geometry.voxel_volume();
  return volumes;
}

// The labels of `volume` (every value but the outside), in increasing order.
inline std::vector<int32_t> label_values(const volume::LabelVolume& volume) {
  std::vector<int32_t> labels;
  for (const auto& label : volume::compute_label_statistics(volume).labels)
    labels.push_back(label.label);
  return labels;
}

}  // namespace labelmesh::testing
