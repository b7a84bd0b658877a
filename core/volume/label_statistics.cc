// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/label_statistics.h"

#include <algorithm>
#include <limits>
#include <type_traits>

#include "absl/container/flat_hash_map.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::volume {
namespace {

struct Tally {
  uint64_t voxels = 0;
  std::array<int64_t, 3> min_index{std::numeric_limits<int64_t>::max(),
                                   std::numeric_limits<int64_t>::max(),
                                   std::numeric_limits<int64_t>::max()};
  std::array<int64_t, 3> max_index{-1, -1, -1};
};

// Maps a label value to its tally: a direct table for narrow types.
template <typename T>
class TallyTable {
 public:
  Tally& at(T value) {
    if constexpr (sizeof(T) <= 2) {
      return table_[static_cast<size_t>(static_cast<int64_t>(value) -
                                        std::numeric_limits<T>::min())];
    } else {
      return map_[value];
    }
  }

  template <typename F>
  void for_each(F&& f) const {
    if constexpr (sizeof(T) <= 2) {
      for (size_t slot = 0; slot < table_.size(); ++slot) {
        if (table_[slot].voxels > 0) {
          f(static_cast<int32_t>(static_cast<int64_t>(slot) + std::numeric_limits<T>::min()),
            table_[slot]);
        }
      }
    } else {
      for (const auto& [value, tally] : map_) f(static_cast<int32_t>(value), tally);
    }
  }

 private:
  static constexpr size_t kTableSize = sizeof(T) <= 2 ? (size_t{1} << (8 * sizeof(T))) : 0;
  std::vector<Tally> table_ = std::vector<Tally>(kTableSize);
  absl::flat_hash_map<T, Tally> map_;
};

template <typename T>
VolumeStatistics tally_labels(const T* voxels, const ImageGeometry& geometry) {
  TallyTable<T> tallies;
  uint64_t background = 0;
  const int64_t nx = geometry.dims[0], ny = geometry.dims[1], nz = geometry.dims[2];
  for (int64_t k = 0; k < nz; ++k) {
    for (int64_t j = 0; j < ny; ++j) {
      const T* row = voxels + (k * ny + j) * nx;
      int64_t i = 0;
      while (i < nx) {
        const T value = row[i];
        // Runs of one label are common: count a run at once.
        int64_t end = i + 1;
        while (end < nx && row[end] == value) ++end;
        if (value == 0) {
          background += static_cast<uint64_t>(end - i);
        } else {
          Tally& tally = tallies.at(value);
          tally.voxels += static_cast<uint64_t>(end - i);
          tally.min_index = {std::min(tally.min_index[0], i), std::min(tally.min_index[1], j),
                             std::min(tally.min_index[2], k)};
          tally.max_index = {std::max(tally.max_index[0], end - 1), std::max(tally.max_index[1], j),
                             std::max(tally.max_index[2], k)};
        }
        i = end;
      }
    }
  }
  VolumeStatistics statistics;
  statistics.background_voxels = background;
  tallies.for_each([&](int32_t label, const Tally& tally) {
    statistics.labels.push_back({label, tally.voxels, tally.min_index, tally.max_index});
  });
  std::sort(statistics.labels.begin(), statistics.labels.end(),
            [](const LabelStatistics& a, const LabelStatistics& b) { return a.label < b.label; });
  return statistics;
}

}  // namespace

const LabelStatistics* VolumeStatistics::find(int32_t label) const {
  auto it =
      std::lower_bound(labels.begin(), labels.end(), label,
                       [](const LabelStatistics& s, int32_t value) { return s.label < value; });
  return it != labels.end() && it->label == label ? &*it : nullptr;
}

VolumeStatistics compute_label_statistics(const LabelVolume& volume) {
  VolumeStatistics statistics;
  visit_voxels(volume.voxels, [&](const auto* voxels, size_t) {
    statistics = tally_labels(voxels, volume.geometry);
  });
  return statistics;
}

}  // namespace labelmesh::volume
