// SPDX-License-Identifier: AGPL-3.0-or-later
// What the surface benchmarks share: our options (tunable from the
// environment), a volume file read with its labels, and the median.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "core/pipeline/pipeline.h"
#include "core/volume/label_statistics.h"
#include "core/volume/read_label_volume.h"

namespace labelmesh::bench {

// The middle of `v` (0 when empty).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Default options, or the net's from LABELMESH_NET_ROUNDS, _THIN_FACTOR,
// _INFLATE, _CUBE, _THICK, _WIDEN and _PAUSES, and with LABELMESH_NET_ONLY the net
// alone (for tuning).
inline MeshParams our_params() {
  MeshParams params;
  if (const char* v = std::getenv("LABELMESH_NET_ROUNDS"))
    params.net.smoothing_rounds = std::atoi(v);
  if (const char* v = std::getenv("LABELMESH_NET_THIN_FACTOR"))
    params.net.thin_grid_rounds_factor = std::atoi(v);
  if (const char* v = std::getenv("LABELMESH_NET_INFLATE")) params.net.inflate_step = std::atof(v);
  if (std::getenv("LABELMESH_NET_ONLY")) {
    params.net.poisson_max_anisotropy = 0;
    params.guard.fall_back = false;
  }
  if (std::getenv("LABELMESH_NET_NO_RESTORE")) params.net.restore_volumes = false;
  if (const char* v = std::getenv("LABELMESH_NET_PAUSES")) params.net.volume_pauses = std::atoi(v);
  if (const char* v = std::getenv("LABELMESH_NET_CUBE")) params.net.cube_fraction = std::atof(v);
  if (const char* v = std::getenv("LABELMESH_NET_THICK")) params.net.thick_ratio = std::atof(v);
  if (const char* v = std::getenv("LABELMESH_NET_WIDEN"))
    params.net.between_drawn_widening = std::atof(v);
  return params;
}

// A volume file read, with its labels (every one, in statistics order).
struct ReadVolume {
  volume::LabelVolume volume;
  volume::VolumeStatistics statistics;
  std::vector<int32_t> labels;
};

inline std::optional<ReadVolume> read_volume(const std::string& path) {
  auto volume = volume::read_label_volume(path, {}, RunContext{});
  if (!volume.ok()) return std::nullopt;
  ReadVolume read{std::move(*volume), {}, {}};
  read.statistics = volume::compute_label_statistics(read.volume);
  for (const auto& l : read.statistics.labels) read.labels.push_back(l.label);
  return read;
}

}  // namespace labelmesh::bench
