// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/label_components.h"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/util/disjoint_sets.h"
#include "core/util/status_macros.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::volume {
namespace {

// The label's bounding box padded by one voxel, so neighbour lookups of label
// voxels never leave it.
struct Box {
  std::array<int64_t, 3> origin;  // index of the box's first voxel in the volume
  std::array<int64_t, 3> size;
  int64_t count() const { return size[0] * size[1] * size[2]; }
  int64_t index(int64_t i, int64_t j, int64_t k) const { return i + size[0] * (j + size[1] * k); }
};

template <typename T>
void fill_mask(const T* voxels, const ImageGeometry& geometry, int32_t label, const Box& box,
               std::vector<uint8_t>& mask) {
  const int64_t nx = geometry.dims[0], ny = geometry.dims[1];
  for (int64_t k = 1; k + 1 < box.size[2]; ++k) {
    for (int64_t j = 1; j + 1 < box.size[1]; ++j) {
      // Index of box voxel (0, j, k) in the volume; i >= 1 keeps it inside.
      const int64_t row = nx * (box.origin[1] + j + ny * (box.origin[2] + k)) + box.origin[0];
      for (int64_t i = 1; i + 1 < box.size[0]; ++i) {
        mask[static_cast<size_t>(box.index(i, j, k))] =
            static_cast<int32_t>(voxels[row + i]) == label ? 1 : 0;
      }
    }
  }
}

// Removes, repeatedly, voxels with at most one face neighbour: strands one
// voxel thick, which no smooth surface at this resolution can follow.
uint64_t prune_strands(const Box& box, std::vector<uint8_t>& mask) {
  const int64_t steps[6] = {
      1, -1, box.size[0], -box.size[0], box.size[0] * box.size[1], -box.size[0] * box.size[1]};
  auto face_neighbours = [&](int64_t n) {
    int count = 0;
    for (int64_t step : steps) count += mask[static_cast<size_t>(n + step)];
    return count;
  };
  std::vector<int64_t> queue;
  for (int64_t n = 0; n < box.count(); ++n) {
    if (mask[static_cast<size_t>(n)] && face_neighbours(n) <= 1) queue.push_back(n);
  }
  uint64_t pruned = 0;
  while (!queue.empty()) {
    const int64_t n = queue.back();
    queue.pop_back();
    if (!mask[static_cast<size_t>(n)] || face_neighbours(n) > 1) continue;
    mask[static_cast<size_t>(n)] = 0;
    ++pruned;
    for (int64_t step : steps) {
      const int64_t m = n + step;
      if (mask[static_cast<size_t>(m)] && face_neighbours(m) <= 1) queue.push_back(m);
    }
  }
  return pruned;
}

// Fills the background pockets of `mask` that the label encloses and that
// hold fewer than `below` voxels. Background is taken 6-connected because the
// label is 26-connected: a pocket that touches the outside only at an edge or
// a corner is enclosed, as its Marching Cubes surface is closed.
//
// Every voxel of an enclosed pocket has label voxels on both sides along each
// axis (a straight line cannot leave the pocket except into the label), so
// only such voxels are flooded, and a flood that reaches any other background
// voxel, or `below` voxels, is an open or large pocket and stays as it is.
// That keeps the work near one pass over the box.
void fill_small_cavities(const Box& box, uint64_t below, std::vector<uint8_t>& mask,
                         uint32_t& cavities, uint64_t& voxels) {
  constexpr uint8_t kOpen = 2;
  const int64_t nx = box.size[0], ny = box.size[1], nz = box.size[2];
  // The first and last label voxel of every row along x, y and z.
  constexpr int64_t kNone = -1;
  std::vector<int64_t> x_first(ny * nz, kNone), x_last(ny * nz, kNone);
  std::vector<int64_t> y_first(nx * nz, kNone), y_last(nx * nz, kNone);
  std::vector<int64_t> z_first(nx * ny, kNone), z_last(nx * ny, kNone);
  auto extend = [](int64_t& first, int64_t& last, int64_t at) {
    if (first == kNone) first = at;
    last = at;
  };
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        if (!mask[static_cast<size_t>(box.index(i, j, k))]) continue;
        extend(x_first[j + ny * k], x_last[j + ny * k], i);
        extend(y_first[i + nx * k], y_last[i + nx * k], j);
        extend(z_first[i + nx * j], z_last[i + nx * j], k);
      }
  auto between = [](int64_t first, int64_t last, int64_t at) {
    return first != kNone && first < at && at < last;
  };
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        auto& m = mask[static_cast<size_t>(box.index(i, j, k))];
        if (m) continue;
        const bool enclosed = between(x_first[j + ny * k], x_last[j + ny * k], i) &&
                              between(y_first[i + nx * k], y_last[i + nx * k], j) &&
                              between(z_first[i + nx * j], z_last[i + nx * j], k);
        if (!enclosed) m = kOpen;
      }

  const int64_t steps[6] = {1, -1, nx, -nx, nx * ny, -nx * ny};
  constexpr uint8_t kVisiting = 3;
  std::vector<int64_t> stack, region;
  for (int64_t n = 0; n < box.count(); ++n) {
    if (mask[static_cast<size_t>(n)] != 0) continue;
    // Enclosed voxels are inside the box's outer layer, so every step stays
    // in the box.
    region.clear();
    bool open = false;
    mask[static_cast<size_t>(n)] = kVisiting;
    stack.push_back(n);
    while (!stack.empty() && !open && region.size() < below) {
      const int64_t at = stack.back();
      stack.pop_back();
      region.push_back(at);
      for (int64_t step : steps) {
        auto& m = mask[static_cast<size_t>(at + step)];
        if (m == kOpen) {
          open = true;
        } else if (m == 0) {
          m = kVisiting;
          stack.push_back(at + step);
        }
      }
    }
    const bool fill = !open && stack.empty() && region.size() < below;
    // What is left unvisited of an open or large pocket meets these marks
    // later and is found open too.
    for (int64_t at : region) mask[static_cast<size_t>(at)] = fill ? 1 : kOpen;
    for (int64_t at : stack) mask[static_cast<size_t>(at)] = kOpen;
    stack.clear();
    if (!fill) continue;
    ++cavities;
    voxels += region.size();
  }
  for (auto& m : mask) m = m == 1 ? 1 : 0;
}

// A row's stretch of label voxels, i in [begin, end), in row j + ny * k.
struct Run {
  int64_t row;
  int64_t begin, end;
};

// The mask's runs in memory order, and where each row's runs start in them.
struct Runs {
  std::vector<Run> runs;
  std::vector<size_t> row_start;  // one per row, and one past the last
};

absl::StatusOr<Runs> find_runs(const Box& box, const std::vector<uint8_t>& mask,
                               const RunContext& context) {
  Runs result;
  const int64_t rows = box.size[1] * box.size[2];
  result.row_start.reserve(static_cast<size_t>(rows) + 1);
  for (int64_t row = 0; row < rows; ++row) {
    if (row % box.size[1] == 0) {
      LABELMESH_RETURN_IF_ERROR(context.check_stop());
    }
    result.row_start.push_back(result.runs.size());
    const uint8_t* voxels = mask.data() + row * box.size[0];
    // The box's padding keeps the first and last voxel of a row empty.
    for (int64_t i = 1; i + 1 < box.size[0]; ++i) {
      if (!voxels[i]) continue;
      const int64_t begin = i;
      while (voxels[i]) ++i;
      result.runs.push_back({row, begin, i});
    }
  }
  result.row_start.push_back(result.runs.size());
  return result;
}

// One set per run, united with the runs it touches (26-connected: overlapping
// or meeting at a corner, i within one) in the four neighbouring rows that
// come before it in memory order. Working on runs rather than voxels keeps
// the union-find to about one entry per row of the organ.
geometry::DisjointSets label_runs(const Box& box, const Runs& runs) {
  geometry::DisjointSets sets(runs.runs.size());
  const int64_t ny = box.size[1];
  for (size_t r = 0; r < runs.runs.size(); ++r) {
    const Run& run = runs.runs[r];
    const int64_t j = run.row % ny, k = run.row / ny;
    const int64_t earlier[4][2] = {{j - 1, k}, {j - 1, k - 1}, {j, k - 1}, {j + 1, k - 1}};
    for (const auto& [nj, nk] : earlier) {
      if (nj < 0 || nj >= ny || nk < 0) continue;
      const size_t row = static_cast<size_t>(nj + ny * nk);
      const auto first = runs.runs.begin() + static_cast<std::ptrdiff_t>(runs.row_start[row]);
      const auto last = runs.runs.begin() + static_cast<std::ptrdiff_t>(runs.row_start[row + 1]);
      // The first run in that row that ends at or past run.begin - 1.
      auto other =
          std::partition_point(first, last, [&](const Run& o) { return o.end < run.begin; });
      for (; other != last && other->begin <= run.end; ++other)
        sets.unite(static_cast<uint32_t>(r), static_cast<uint32_t>(other - runs.runs.begin()));
    }
  }
  return sets;
}

}  // namespace

absl::StatusOr<LabelComponents> find_label_components(const LabelVolume& volume,
                                                      const LabelStatistics& label,
                                                      const ComponentOptions& options,
                                                      const RunContext& context) {
  Box box;
  for (int axis = 0; axis < 3; ++axis) {
    box.origin[axis] = label.min_index[axis] - 1;
    box.size[axis] = label.max_index[axis] - label.min_index[axis] + 3;
  }
  if (box.count() >= int64_t{1} << 32) {
    return absl::InvalidArgumentError("label components: the label's bounding box is too large");
  }
  std::vector<uint8_t> mask(static_cast<size_t>(box.count()), 0);
  const bool typed = visit_voxels(volume.voxels, [&](const auto* voxels, size_t) {
    fill_mask(voxels, volume.geometry, label.label, box, mask);
  });
  if (!typed) return absl::InternalError("label components: unsupported voxel type in memory");
  LabelComponents result;
  if (options.prune_strands) result.pruned_voxels = prune_strands(box, mask);
  if (options.fill_cavities_below > 0) {
    fill_small_cavities(box, options.fill_cavities_below, mask, result.filled_cavities,
                        result.filled_voxels);
  }

  LABELMESH_ASSIGN_OR_RETURN(auto runs, find_runs(box, mask, context));
  context.report("components", 0.5);
  geometry::DisjointSets sets = label_runs(box, runs);

  // Ids in order of first appearance: runs are in memory order.
  result.ids = vtkSmartPointer<vtkImageData>::New();
  result.ids->SetExtent(
      static_cast<int>(box.origin[0]), static_cast<int>(box.origin[0] + box.size[0] - 1),
      static_cast<int>(box.origin[1]), static_cast<int>(box.origin[1] + box.size[1] - 1),
      static_cast<int>(box.origin[2]), static_cast<int>(box.origin[2] + box.size[2] - 1));
  result.ids->SetSpacing(volume.voxels->GetSpacing());
  result.ids->SetOrigin(volume.voxels->GetOrigin());
  result.ids->AllocateScalars(VTK_INT, 1);
  auto* ids = static_cast<int32_t*>(result.ids->GetScalarPointer());
  std::fill(ids, ids + box.count(), 0);
  std::vector<int32_t> id_of_root(sets.size(), 0);
  for (size_t r = 0; r < runs.runs.size(); ++r) {
    const Run& run = runs.runs[r];
    int32_t& id = id_of_root[sets.find(static_cast<uint32_t>(r))];
    if (id == 0) {
      LabelComponent component;
      component.id = static_cast<int32_t>(result.components.size() + 1);
      component.min_index = {std::numeric_limits<int64_t>::max(),
                             std::numeric_limits<int64_t>::max(),
                             std::numeric_limits<int64_t>::max()};
      component.max_index = {-1, -1, -1};
      result.components.push_back(component);
      id = component.id;
    }
    const int64_t j = run.row % box.size[1], k = run.row / box.size[1];
    std::fill(ids + box.index(run.begin, j, k), ids + box.index(run.end, j, k), id);
    auto& component = result.components[static_cast<size_t>(id - 1)];
    component.voxels += static_cast<uint64_t>(run.end - run.begin);
    const std::array<int64_t, 3> low{box.origin[0] + run.begin, box.origin[1] + j,
                                     box.origin[2] + k};
    const std::array<int64_t, 3> high{box.origin[0] + run.end - 1, low[1], low[2]};
    for (int axis = 0; axis < 3; ++axis) {
      component.min_index[axis] = std::min(component.min_index[axis], low[axis]);
      component.max_index[axis] = std::max(component.max_index[axis], high[axis]);
    }
  }
  context.report("components", 1);
  return result;
}

}  // namespace labelmesh::volume
