// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/label_components.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "core/volume/label_statistics.h"
#include "support/label_grid.h"
#include "support/status_matchers.h"

namespace labelmesh::volume {
namespace {

LabelComponents components_of(const LabelVolume& v, int32_t label, bool prune) {
  const auto stats = compute_label_statistics(v);
  const auto* entry = stats.find(label);
  EXPECT_NE(entry, nullptr);
  ComponentOptions options;
  options.prune_strands = prune;
  auto found = find_label_components(v, *entry, options, RunContext{});
  EXPECT_THAT(found, testing::IsOk());
  return found.ok() ? std::move(*found) : LabelComponents{};
}

bool in_box(int i, int j, int k, int lo, int hi) {
  return i >= lo && i <= hi && j >= lo && j <= hi && k >= lo && k <= hi;
}

TEST(LabelComponents, SeparateBlocksAreSeparateAndCornersJoin) {
  // Two 3x3x3 blocks apart, plus a single voxel touching the first by a corner.
  const auto v = testing::label_grid({14, 14, 14}, [](int i, int j, int k) -> uint8_t {
    if (in_box(i, j, k, 1, 3) || in_box(i, j, k, 8, 10)) return 1;
    return (i == 4 && j == 4 && k == 4) ? 1 : 0;
  });
  const auto found = components_of(v, 1, /*prune=*/false);
  ASSERT_EQ(found.components.size(), 2u);
  EXPECT_EQ(found.components[0].voxels, 28u);  // 27 + the corner voxel
  EXPECT_EQ(found.components[1].voxels, 27u);
  EXPECT_EQ(found.components[1].min_index, (std::array<int64_t, 3>{8, 8, 8}));
  EXPECT_EQ(found.components[1].max_index, (std::array<int64_t, 3>{10, 10, 10}));
  EXPECT_EQ(found.pruned_voxels, 0u);
  // The id image covers the label's box plus one voxel and holds ids 1 and 2.
  int extent[6];
  found.ids->GetExtent(extent);
  EXPECT_EQ(extent[0], 0);
  EXPECT_EQ(extent[1], 11);
  EXPECT_EQ(*static_cast<int32_t*>(found.ids->GetScalarPointer(9, 9, 9)), 2);
  EXPECT_EQ(*static_cast<int32_t*>(found.ids->GetScalarPointer(4, 4, 4)), 1);
  EXPECT_EQ(*static_cast<int32_t*>(found.ids->GetScalarPointer(6, 6, 6)), 0);
}

TEST(LabelComponents, OneVoxelStrandsArePruned) {
  // A 5x5x5 block with a 3-voxel strand sticking out along x, and a separate
  // 1-voxel-thick line of 4 voxels.
  const auto v = testing::label_grid({16, 12, 12}, [](int i, int j, int k) -> uint8_t {
    if (in_box(i, j, k, 1, 5)) return 1;
    if (j == 3 && k == 3 && i >= 6 && i <= 8) return 1;   // strand on the block
    if (i == 12 && j == 8 && k >= 2 && k <= 5) return 1;  // lone line
    return 0;
  });
  const auto kept = components_of(v, 1, /*prune=*/false);
  EXPECT_EQ(kept.components.size(), 2u);
  EXPECT_EQ(kept.pruned_voxels, 0u);
  const auto pruned = components_of(v, 1, /*prune=*/true);
  ASSERT_EQ(pruned.components.size(), 1u);
  EXPECT_EQ(pruned.pruned_voxels, 7u);
  EXPECT_EQ(pruned.components[0].voxels, 125u);
  EXPECT_EQ(pruned.components[0].max_index, (std::array<int64_t, 3>{5, 5, 5}));
}

// Random sparse masks, labelled by a plain flood fill over all 26
// neighbours: every voxel gets the same partition as the scan's (ids in the
// same order of first voxel), whatever shortcut the scan takes.
TEST(LabelComponents, MatchAFloodFillOnRandomMasks) {
  constexpr int kSize = 18;
  std::mt19937 random(5);
  for (int round = 0; round < 30; ++round) {
    // Rounds 0-19: single voxels, from dust to one tangle. Rounds 20-29:
    // stretches along rows, which meet the rows around them at their ends.
    const bool stretches = round >= 20;
    const double density = stretches ? 0.05 + 0.01 * (round - 20) : 0.1 + 0.02 * round;
    std::bernoulli_distribution filled(density), goes_on(0.8);
    std::vector<uint8_t> mask(kSize * kSize * kSize, 0);
    auto at = [](int i, int j, int k) { return i + kSize * (j + kSize * k); };
    for (int k = 1; k + 1 < kSize; ++k)
      for (int j = 1; j + 1 < kSize; ++j)
        for (int i = 1; i + 1 < kSize; ++i) {
          if (!filled(random)) continue;
          mask[at(i, j, k)] = 1;
          while (stretches && i + 2 < kSize && goes_on(random)) mask[at(++i, j, k)] = 1;
        }
    const auto v = testing::label_grid(
        {kSize, kSize, kSize}, [&](int i, int j, int k) -> uint8_t { return mask[at(i, j, k)]; });
    const auto found = components_of(v, 1, /*prune=*/false);

    std::vector<int32_t> flood(mask.size(), 0);
    int32_t next = 0;
    for (int start = 0; start < int(mask.size()); ++start) {
      if (!mask[start] || flood[start] != 0) continue;
      flood[start] = ++next;
      std::vector<int> stack{start};
      while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        const int i = n % kSize, j = n / kSize % kSize, k = n / (kSize * kSize);
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int m = at(i + di, j + dj, k + dk);
              if (mask[m] && flood[m] == 0) {
                flood[m] = next;
                stack.push_back(m);
              }
            }
      }
    }
    ASSERT_EQ(found.components.size(), size_t(next)) << "density " << density;
    // Each component's voxel count and box, from the flood.
    std::vector<uint64_t> voxels(size_t(next) + 1, 0);
    std::vector<std::array<int64_t, 3>> low(size_t(next) + 1, {kSize, kSize, kSize}),
        high(size_t(next) + 1, {-1, -1, -1});
    for (int n = 0; n < int(mask.size()); ++n) {
      if (flood[n] == 0) continue;
      const std::array<int64_t, 3> ijk{n % kSize, n / kSize % kSize, n / (kSize * kSize)};
      ++voxels[flood[n]];
      for (int axis = 0; axis < 3; ++axis) {
        low[flood[n]][axis] = std::min(low[flood[n]][axis], ijk[axis]);
        high[flood[n]][axis] = std::max(high[flood[n]][axis], ijk[axis]);
      }
    }
    for (const auto& component : found.components) {
      EXPECT_EQ(component.voxels, voxels[component.id]) << "density " << density;
      EXPECT_EQ(component.min_index, low[component.id]) << "density " << density;
      EXPECT_EQ(component.max_index, high[component.id]) << "density " << density;
    }
    int extent[6];
    found.ids->GetExtent(extent);
    for (int k = extent[4]; k <= extent[5]; ++k)
      for (int j = extent[2]; j <= extent[3]; ++j)
        for (int i = extent[0]; i <= extent[1]; ++i) {
          ASSERT_EQ(*static_cast<int32_t*>(found.ids->GetScalarPointer(i, j, k)),
                    flood[at(i, j, k)])
              << "density " << density << " at " << i << " " << j << " " << k;
        }
  }
}

TEST(LabelComponents, SmallCavitiesAreFilledLargeAndOpenOnesKept) {
  // A 14^3 block holding a 1-voxel hole, a 2x2x2 hole, a 4x4x4 hole (64
  // voxels: not under the threshold of 64) and a 1x1x3 notch open to the
  // outside through a face.
  const auto v = testing::label_grid({18, 18, 18}, [](int i, int j, int k) -> uint8_t {
    if (!in_box(i, j, k, 2, 15)) return 0;
    if (i == 4 && j == 4 && k == 4) return 0;                                   // 1 voxel
    if (i >= 7 && i <= 8 && j >= 4 && j <= 5 && k >= 4 && k <= 5) return 0;     // 8 voxels
    if (i >= 9 && i <= 12 && j >= 9 && j <= 12 && k >= 9 && k <= 12) return 0;  // 64 voxels
    if (i == 6 && j == 13 && k >= 13) return 0;                                 // open notch
    return 1;
  });
  ComponentOptions options;
  options.prune_strands = false;
  options.fill_cavities_below = 64;
  const auto stats = compute_label_statistics(v);
  const auto found = find_label_components(v, stats.labels[0], options, RunContext{});
  ASSERT_THAT(found, testing::IsOk());
  EXPECT_EQ(found->filled_cavities, 2u);
  EXPECT_EQ(found->filled_voxels, 9u);
  ASSERT_EQ(found->components.size(), 1u);
  EXPECT_EQ(found->components[0].voxels, 14u * 14 * 14 - 64 - 3);
  auto id_at = [&](int i, int j, int k) {
    return *static_cast<int32_t*>(found->ids->GetScalarPointer(i, j, k));
  };
  EXPECT_EQ(id_at(4, 4, 4), 1);
  EXPECT_EQ(id_at(8, 5, 5), 1);
  EXPECT_EQ(id_at(10, 10, 10), 0);
  EXPECT_EQ(id_at(6, 13, 14), 0);

  // Off by default: nothing filled.
  options.fill_cavities_below = 0;
  const auto kept = find_label_components(v, stats.labels[0], options, RunContext{});
  ASSERT_THAT(kept, testing::IsOk());
  EXPECT_EQ(kept->filled_cavities, 0u);
  EXPECT_EQ(kept->components[0].voxels, 14u * 14 * 14 - 64 - 3 - 9);
}

// Random dense masks, whose holes are many and of every size: the filled
// voxels are exactly the background 6-components that a flood from the box's
// border never reaches and that hold fewer than the threshold.
TEST(LabelComponents, FilledCavitiesMatchAFloodFromOutside) {
  constexpr int kSize = 16;
  constexpr uint64_t kBelow = 6;
  std::mt19937 random(9);
  auto at = [](int i, int j, int k) { return i + kSize * (j + kSize * k); };
  for (int round = 0; round < 20; ++round) {
    std::bernoulli_distribution filled(0.6 + 0.015 * round);
    std::vector<uint8_t> mask(kSize * kSize * kSize, 0);
    for (int k = 1; k + 1 < kSize; ++k)
      for (int j = 1; j + 1 < kSize; ++j)
        for (int i = 1; i + 1 < kSize; ++i) mask[at(i, j, k)] = filled(random) ? 1 : 0;
    const auto v = testing::label_grid(
        {kSize, kSize, kSize}, [&](int i, int j, int k) -> uint8_t { return mask[at(i, j, k)]; });
    // Background 6-components; those touching the border are outside.
    std::vector<int> component(mask.size(), -1);
    std::vector<size_t> sizes;
    std::vector<bool> outside;
    for (int start = 0; start < int(mask.size()); ++start) {
      if (mask[start] || component[start] >= 0) continue;
      const int id = int(sizes.size());
      sizes.push_back(0);
      outside.push_back(false);
      std::vector<int> stack{start};
      component[start] = id;
      while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        ++sizes[id];
        const int i = n % kSize, j = n / kSize % kSize, k = n / (kSize * kSize);
        const std::array<int, 3> here{i, j, k};
        for (int axis = 0; axis < 3; ++axis) {
          for (int d : {-1, 1}) {
            std::array<int, 3> next = here;
            next[axis] += d;
            if (next[axis] < 0 || next[axis] >= kSize) {
              outside[id] = true;  // the box's border is open
              continue;
            }
            const int m = at(next[0], next[1], next[2]);
            if (!mask[m] && component[m] < 0) {
              component[m] = id;
              stack.push_back(m);
            }
          }
        }
      }
    }
    uint64_t expected_voxels = 0;
    uint32_t expected_cavities = 0;
    for (size_t id = 0; id < sizes.size(); ++id) {
      if (outside[id] || sizes[id] >= kBelow) continue;
      ++expected_cavities;
      expected_voxels += sizes[id];
    }
    ComponentOptions options;
    options.prune_strands = false;
    options.fill_cavities_below = kBelow;
    const auto stats = compute_label_statistics(v);
    const auto found = find_label_components(v, stats.labels[0], options, RunContext{});
    ASSERT_THAT(found, testing::IsOk());
    EXPECT_EQ(found->filled_cavities, expected_cavities) << "round " << round;
    EXPECT_EQ(found->filled_voxels, expected_voxels) << "round " << round;
    int extent[6];
    found->ids->GetExtent(extent);
    for (int k = extent[4]; k <= extent[5]; ++k)
      for (int j = extent[2]; j <= extent[3]; ++j)
        for (int i = extent[0]; i <= extent[1]; ++i) {
          const int n = at(i, j, k);
          const bool labelled = *static_cast<int32_t*>(found->ids->GetScalarPointer(i, j, k)) != 0;
          const bool should = mask[n] || (!outside[component[n]] && sizes[component[n]] < kBelow);
          ASSERT_EQ(labelled, should) << "round " << round << " at " << i << " " << j << " " << k;
        }
  }
}

TEST(LabelComponents, APocketTouchingTheOutsideOnlyAtAnEdgeIsEnclosed) {
  // A 6^3 block with a notch at its edge voxel (3, 3, 5), open to the
  // outside, and a pocket at (4, 4, 5), which shares only an edge with the
  // notch. The label is 26-connected, so background counts as 6-connected:
  // the pocket is enclosed (its Marching Cubes surface is closed).
  const auto v = testing::label_grid({10, 10, 10}, [](int i, int j, int k) -> uint8_t {
    if (!in_box(i, j, k, 3, 8)) return 0;
    if (k == 5 && ((i == 3 && j == 3) || (i == 4 && j == 4))) return 0;
    return 1;
  });
  ComponentOptions options;
  options.fill_cavities_below = 64;
  const auto stats = compute_label_statistics(v);
  const auto found = find_label_components(v, stats.labels[0], options, RunContext{});
  ASSERT_THAT(found, testing::IsOk());
  EXPECT_EQ(found->filled_cavities, 1u);
  EXPECT_EQ(found->filled_voxels, 1u);
  EXPECT_EQ(*static_cast<int32_t*>(found->ids->GetScalarPointer(4, 4, 5)), 1);
  EXPECT_EQ(*static_cast<int32_t*>(found->ids->GetScalarPointer(3, 3, 5)), 0);
}

TEST(LabelComponents, CancelledRunStops) {
  const auto v = testing::label_grid({8, 8, 8}, [](int, int, int) -> uint8_t { return 1; });
  const auto stats = compute_label_statistics(v);
  std::atomic<bool> stop{true};
  RunContext context;
  context.stop = &stop;
  auto found = find_label_components(v, stats.labels[0], ComponentOptions{}, context);
  EXPECT_THAT(found, testing::StatusIs(absl::StatusCode::kCancelled));
}

}  // namespace
}  // namespace labelmesh::volume
