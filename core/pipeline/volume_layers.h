// SPDX-License-Identifier: AGPL-3.0-or-later
// Overlapping segments kept apart by the reader (LabelVolume::more_layers)
// are meshed layer by layer: each layer is an ordinary label volume, and
// every label lives in exactly one of them.
#pragma once

#include <vector>

#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"

namespace labelmesh {

// The volume's layers as label volumes on the same grid, sharing its voxels:
// `volume` itself (without more_layers) first, then each further layer.
std::vector<volume::LabelVolume> volume_layers(const volume::LabelVolume& volume);

// The statistics of every label over all layers, and as background the
// voxels no layer labels.
volume::VolumeStatistics layered_statistics(const std::vector<volume::LabelVolume>& layers);

}  // namespace labelmesh
