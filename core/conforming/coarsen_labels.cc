// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/coarsen_labels.h"

#include <vtkImageData.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/util/text.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::conforming {
namespace {

// The volume's labels as int32, unselected ones 0.
std::vector<int32_t> selected_labels(const volume::LabelVolume& volume,
                                     std::vector<int32_t> selected) {
  std::sort(selected.begin(), selected.end());
  std::vector<int32_t> out(static_cast<size_t>(volume.geometry.voxel_count()), 0);
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    for (size_t i = 0; i < std::min(count, out.size()); ++i) {
      const auto label = static_cast<int32_t>(voxels[i]);
      if (selected.empty() || std::binary_search(selected.begin(), selected.end(), label))
        out[i] = label;
    }
  });
  return out;
}

}  // namespace

Coarsening choose_coarsening(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                             uint64_t max_interface_faces) {
  Coarsening coarsening;
  const auto voxels = selected_labels(volume, labels);
  const auto& d = volume.geometry.dims;
  const int64_t stride[3] = {1, d[0], d[0] * d[1]};
  for (int64_t z = 0; z < d[2]; ++z) {
    for (int64_t y = 0; y < d[1]; ++y) {
      for (int64_t x = 0; x < d[0]; ++x) {
        const int64_t i = x + y * stride[1] + z * stride[2];
        const int64_t at[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
          if (at[a] + 1 < d[a]) coarsening.interface_faces += voxels[i] != voxels[i + stride[a]];
        }
        // Faces on the volume's outer walls count too: the padding is outside.
        for (int a = 0; a < 3; ++a) {
          if (voxels[i] != 0 && (at[a] == 0 || at[a] + 1 == d[a])) ++coarsening.interface_faces;
        }
      }
    }
  }
  if (max_interface_faces == 0 || coarsening.interface_faces <= max_interface_faces)
    return coarsening;
  const double scale = std::sqrt(double(coarsening.interface_faces) / double(max_interface_faces));
  const auto& s = volume.geometry.spacing;
  const double least = std::min({s[0], s[1], s[2]});
  for (int a = 0; a < 3; ++a) {
    coarsening.factors[a] = static_cast<int>(
        std::clamp<int64_t>(static_cast<int64_t>(std::ceil(scale * least / s[a] - 1e-9)), 1,
                            std::max<int64_t>(1, d[a])));
  }
  return coarsening;
}

absl::StatusOr<volume::LabelVolume> coarsen_labels(const volume::LabelVolume& volume,
                                                   const std::vector<int32_t>& labels,
                                                   const std::array<int, 3>& factors,
                                                   const RunContext& context) {
  for (int factor : factors) {
    if (factor < 1) return absl::InvalidArgumentError(cat("coarsening: factor ", factor, " < 1"));
  }
  const auto& geometry = volume.geometry;
  volume::LabelVolume coarse;
  coarse.format = volume.format;
  coarse.file_voxel_type = volume.file_voxel_type;
  coarse.descriptions = volume.descriptions;
  coarse.geometry = geometry;
  std::array<double, 3> first{};
  for (int a = 0; a < 3; ++a) {
    coarse.geometry.dims[a] = (geometry.dims[a] + factors[a] - 1) / factors[a];
    coarse.geometry.spacing[a] = geometry.spacing[a] * factors[a];
    first[a] = 0.5 * (factors[a] - 1);
  }
  coarse.geometry.origin = geometry.to_physical(first);
  const auto& cd = coarse.geometry.dims;
  coarse.voxels = vtkSmartPointer<vtkImageData>::New();
  coarse.voxels->SetDimensions(static_cast<int>(cd[0]), static_cast<int>(cd[1]),
                               static_cast<int>(cd[2]));
  coarse.voxels->AllocateScalars(VTK_INT, 1);
  auto* out = static_cast<int32_t*>(coarse.voxels->GetScalarPointer());
  if (out == nullptr) {
    return absl::ResourceExhaustedError(
        cat("coarsening: no memory for ", coarse.geometry.voxel_count(), " voxels"));
  }
  const auto voxels = selected_labels(volume, labels);
  const auto& d = geometry.dims;
  std::vector<std::pair<int32_t, int>> counts;
  for (int64_t z = 0; z < cd[2]; ++z) {
    if (auto status = context.check_stop(); !status.ok()) return status;
    for (int64_t y = 0; y < cd[1]; ++y) {
      for (int64_t x = 0; x < cd[0]; ++x) {
        counts.clear();
        for (int64_t k = z * factors[2]; k < std::min(d[2], (z + 1) * factors[2]); ++k) {
          for (int64_t j = y * factors[1]; j < std::min(d[1], (y + 1) * factors[1]); ++j) {
            for (int64_t i = x * factors[0]; i < std::min(d[0], (x + 1) * factors[0]); ++i) {
              const int32_t label = voxels[static_cast<size_t>(i + d[0] * (j + d[1] * k))];
              auto it = std::find_if(counts.begin(), counts.end(),
                                     [&](const auto& c) { return c.first == label; });
              if (it == counts.end()) {
                counts.push_back({label, 1});
              } else {
                ++it->second;
              }
            }
          }
        }
        const auto winner = std::max_element(counts.begin(), counts.end(), [](auto a, auto b) {
          if (a.second != b.second) return a.second < b.second;
          if ((a.first == 0) != (b.first == 0)) return a.first == 0;  // a label over 0
          return a.first > b.first;                                   // the smaller label
        });
        out[x + cd[0] * (y + cd[1] * z)] = winner->first;
      }
    }
  }
  return coarse;
}

}  // namespace labelmesh::conforming
