// SPDX-License-Identifier: AGPL-3.0-or-later
#include "bench/blur_bench.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "bench/bench_inputs.h"
#include "core/pipeline/surface_fidelity.h"
#include "core/surface/voxel_fidelity.h"
#include "support/gaussian_iso.h"
#include "support/slicer_like.h"

namespace labelmesh::bench {

int bench_blurs(const std::string& path) {
  std::printf("\n%s\n", path.c_str());
  const auto read = read_volume(path);
  const auto result = run_pipeline(path, our_params(), RunContext{});
  if (!read || !result.ok()) {
    std::printf("  failed to read or mesh\n");
    return 1;
  }
  if (result->input.file_geometry)
    std::printf("  (meshed on the grid its labels were drawn on; the blurs run on the file's)\n");
  const auto slicer = testing::slicer_like_surfaces(read->volume, read->statistics, read->labels);
  const std::vector<double> sigmas{0.5, 0.6, 0.7, 0.8, 1.0, 1.5};
  std::vector<std::vector<double>> shares(sigmas.size()), wrong(sigmas.size());
  std::vector<int> within(sigmas.size(), 0), within_all(sigmas.size(), 0);
  std::vector<double> least_within, least_within_all, slicer_share, our_share;
  for (size_t i = 0; i < read->labels.size() && i < slicer.size(); ++i) {
    const auto* label = read->statistics.find(read->labels[i]);
    if (label == nullptr || label->voxels < 1000) continue;
    const SurfaceResult* ours = nullptr;
    for (const auto& s : result->surfaces)
      if (s.label == label->label && s.is_output) ours = &s;
    const auto slicer_voxels =
        surface::measure_voxel_fidelity(slicer[i].mesh, read->volume, *label, {});
    if (ours == nullptr || !ours->axis_aligned_share || !ours->fidelity || !slicer_voxels.ok())
      continue;
    double least = 1, least_all = 1;
    for (size_t k = 0; k < sigmas.size(); ++k) {
      const auto blurred = testing::gaussian_iso_surface(read->volume, *label, sigmas[k]);
      const auto voxels = surface::measure_voxel_fidelity(blurred, read->volume, *label, {});
      if (!voxels.ok()) continue;
      shares[k].push_back(100 * voxels->axis_aligned_share);
      wrong[k].push_back(100 * voxels->misclassified_fraction());
      if (voxels->misclassified_fraction() <= 0.01) {
        ++within[k];
        least = std::min(least, voxels->axis_aligned_share);
      }
      // Every bound of the guard's but the distance, which takes a
      // staircase to measure.
      SurfaceAttempt attempt;
      attempt.voxels = *voxels;
      if (is_within(attempt, ours->fidelity->tolerance)) {
        ++within_all[k];
        least_all = std::min(least_all, voxels->axis_aligned_share);
      }
    }
    least_within.push_back(100 * least);
    least_within_all.push_back(100 * least_all);
    slicer_share.push_back(100 * slicer_voxels->axis_aligned_share);
    our_share.push_back(100 * *ours->axis_aligned_share);
  }
  if (least_within.empty()) {
    std::printf("  no label of 1,000 voxels or more\n");
    return 0;
  }
  for (size_t k = 0; k < sigmas.size(); ++k)
    std::printf(
        "  blur of %.1f voxels: median share %.1f %%, median misclassified %.2f %%, labels "
        "within 1 %%: %d of %zu (within the volume and reach bounds too: %d)\n",
        sigmas[k], median(shares[k]), median(wrong[k]), within[k], shares[k].size(), within_all[k]);
  std::printf(
      "  median over %zu labels: least share within 1 %% by a blur %.1f %% (within the volume "
      "and reach bounds too %.1f %%; none within: 100), Slicer-like %.1f %%, ours %.1f %%\n",
      least_within.size(), median(least_within), median(least_within_all), median(slicer_share),
      median(our_share));
  const auto none = [](const std::vector<double>& least) {
    return std::count(least.begin(), least.end(), 100.0);
  };
  std::printf(
      "  labels no blur keeps within: 1 %% of the centres %td, the volume and reach bounds too "
      "%td\n",
      none(least_within), none(least_within_all));
  return 0;
}

}  // namespace labelmesh::bench
