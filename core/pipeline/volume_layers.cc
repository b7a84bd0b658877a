// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/volume_layers.h"

#include <algorithm>
#include <cstdint>

#include "core/volume/voxel_access.h"

namespace labelmesh {

std::vector<volume::LabelVolume> volume_layers(const volume::LabelVolume& volume) {
  std::vector<volume::LabelVolume> layers;
  volume::LabelVolume first = volume;
  first.more_layers.clear();
  layers.push_back(std::move(first));
  for (const auto& image : volume.more_layers) {
    volume::LabelVolume layer = layers.front();
    layer.voxels = image;
    layers.push_back(std::move(layer));
  }
  return layers;
}

volume::VolumeStatistics layered_statistics(const std::vector<volume::LabelVolume>& layers) {
  volume::VolumeStatistics all;
  if (layers.empty()) return all;
  for (const auto& layer : layers) {
    const auto statistics = volume::compute_label_statistics(layer);
    all.labels.insert(all.labels.end(), statistics.labels.begin(), statistics.labels.end());
  }
  std::sort(all.labels.begin(), all.labels.end(),
            [](const auto& a, const auto& b) { return a.label < b.label; });
  // Background: voxels that are 0 in every layer.
  std::vector<uint8_t> labelled(static_cast<size_t>(layers.front().geometry.voxel_count()), 0);
  for (const auto& layer : layers) {
    volume::visit_voxels(layer.voxels, [&](const auto* voxels, size_t count) {
      for (size_t i = 0; i < std::min(count, labelled.size()); ++i) labelled[i] |= voxels[i] != 0;
    });
  }
  all.background_voxels =
      static_cast<uint64_t>(std::count(labelled.begin(), labelled.end(), uint8_t{0}));
  return all;
}

}  // namespace labelmesh
