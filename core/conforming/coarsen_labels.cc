// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/coarsen_labels.h"

#include <vtkImageData.h>

#include <algorithm>
#include <cmath>

#include "core/util/text.h"
#include "core/volume/drawn_grid.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::conforming {
namespace {

// Calls f(label_at) with label_at(i) the selected label (or 0) of voxel i,
// reading the voxels in their own type: no copy of a large volume.
template <typename F>
void with_selected_labels(const volume::LabelVolume& volume, std::vector<int32_t> selected, F&& f) {
  std::sort(selected.begin(), selected.end());
  const auto voxel_count = static_cast<size_t>(volume.geometry.voxel_count());
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count != voxel_count) return;
    f([&](size_t i) {
      const auto label = static_cast<int32_t>(voxels[i]);
      return selected.empty() || std::binary_search(selected.begin(), selected.end(), label) ? label
                                                                                             : 0;
    });
  });
}

}  // namespace

Coarsening choose_coarsening(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                             uint64_t max_interface_faces) {
  Coarsening coarsening;
  const auto& d = volume.geometry.dims;
  const int64_t stride[3] = {1, d[0], d[0] * d[1]};
  with_selected_labels(volume, labels, [&](const auto& label_at) {
    for (int64_t z = 0; z < d[2]; ++z) {
      for (int64_t y = 0; y < d[1]; ++y) {
        for (int64_t x = 0; x < d[0]; ++x) {
          const auto i = static_cast<size_t>(x + y * stride[1] + z * stride[2]);
          const int32_t label = label_at(i);
          const int64_t at[3] = {x, y, z};
          for (int a = 0; a < 3; ++a) {
            if (at[a] + 1 < d[a]) coarsening.interface_faces += label != label_at(i + stride[a]);
            // Faces on the volume's outer walls count too: beyond is outside.
            if (label != 0 && (at[a] == 0 || at[a] + 1 == d[a])) ++coarsening.interface_faces;
          }
        }
      }
    }
  });
  if (max_interface_faces == 0 || coarsening.interface_faces <= max_interface_faces)
    return coarsening;
  const double scale = std::sqrt(double(coarsening.interface_faces) / double(max_interface_faces));
  const auto& s = volume.geometry.spacing;
  const double least = std::min({s[0], s[1], s[2]});
  for (int a = 0; a < 3; ++a) coarsening.factors[a] = std::max(1.0, scale * least / s[a]);
  return coarsening;
}

absl::StatusOr<volume::LabelVolume> coarsen_labels(const volume::LabelVolume& volume,
                                                   const std::vector<int32_t>& labels,
                                                   const std::array<double, 3>& factors,
                                                   const RunContext& context) {
  for (double factor : factors) {
    if (!(factor >= 1))
      return absl::InvalidArgumentError(cat("coarsening: factor ", factor, " < 1"));
  }
  const auto& geometry = volume.geometry;
  const auto& d = geometry.dims;
  volume::LabelVolume coarse;
  coarse.format = volume.format;
  coarse.file_voxel_type = volume.file_voxel_type;
  coarse.descriptions = volume.descriptions;
  // Blocks of `factors` input voxels from the volume's first edge; each
  // takes the input voxel nearest its centre.
  std::array<volume::DrawnAxis, 3> blocks;
  for (int a = 0; a < 3; ++a) {
    blocks[a].pitch = factors[a];
    blocks[a].first_boundary = -0.5;
    blocks[a].count =
        std::max<int64_t>(1, static_cast<int64_t>(std::ceil(d[a] / factors[a] - 1e-9)));
  }
  volume::DrawnSampling sampling = volume::drawn_sampling(geometry, blocks);
  coarse.geometry = sampling.geometry;
  const auto& nearest = sampling.source;
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
  absl::Status status = absl::OkStatus();
  with_selected_labels(volume, labels, [&](const auto& label_at) {
    for (int64_t z = 0; z < cd[2] && status.ok(); ++z) {
      status = context.check_stop();
      for (int64_t y = 0; y < cd[1]; ++y) {
        for (int64_t x = 0; x < cd[0]; ++x) {
          out[x + cd[0] * (y + cd[1] * z)] = label_at(
              static_cast<size_t>(nearest[0][x] + d[0] * (nearest[1][y] + d[1] * nearest[2][z])));
        }
      }
    }
  });
  if (!status.ok()) return status;
  return coarse;
}

}  // namespace labelmesh::conforming
