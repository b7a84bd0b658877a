// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/labels_crossing.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <utility>

#include "core/surface/crossing_triangles.h"

namespace labelmesh {
namespace {

struct Box {
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void add(const std::array<double, 3>& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  bool meets(const Box& o) const {
    for (int k = 0; k < 3; ++k)
      if (o.hi[k] < lo[k] || o.lo[k] > hi[k]) return false;
    return true;
  }
};

Box box_of(const surface::TriangleMesh& mesh) {
  Box box;
  for (const auto& p : mesh.points) box.add(p);
  return box;
}

// The crossing pairs between `apart` and the triangles of `others` within
// its box `reach`, per other label.
std::map<int32_t, size_t> crossings_with(const SurfaceResult& apart, const Box& reach,
                                         const std::vector<const SurfaceResult*>& others) {
  std::vector<std::array<double, 3>> points = apart.mesh.points;
  std::vector<std::array<uint32_t, 3>> triangles = apart.mesh.triangles;
  const auto own = static_cast<uint32_t>(triangles.size());
  std::vector<uint32_t> among(own);
  for (uint32_t t = 0; t < own; ++t) among[t] = t;
  // The label each added triangle belongs to; only the points of the
  // triangles kept are added (a large neighbour meets most boxes).
  std::vector<int32_t> owner;
  std::vector<uint32_t> added;
  for (const auto* other : others) {
    added.assign(other->mesh.points.size(), UINT32_MAX);
    for (const auto& t : other->mesh.triangles) {
      Box box;
      for (const uint32_t v : t) box.add(other->mesh.points[v]);
      if (!reach.meets(box)) continue;
      std::array<uint32_t, 3> kept{};
      for (int k = 0; k < 3; ++k) {
        auto& at = added[t[k]];
        if (at == UINT32_MAX) {
          at = static_cast<uint32_t>(points.size());
          points.push_back(other->mesh.points[t[k]]);
        }
        kept[k] = at;
      }
      triangles.push_back(kept);
      owner.push_back(other->label);
    }
  }
  std::map<int32_t, size_t> pairs;
  if (triangles.size() == own) return pairs;
  for (const auto& [a, b] : surface::crossing_triangles_near(points, triangles, among))
    if (a < own && b >= own) ++pairs[owner[b - own]];
  return pairs;
}

}  // namespace

std::vector<LabelsCrossing> labels_crossing(
    const std::vector<SurfaceResult>& surfaces,
    const std::vector<std::pair<int32_t, size_t>>& layer_of) {
  auto sorted = layer_of;
  std::sort(sorted.begin(), sorted.end());
  const auto layer = [&](int32_t label) -> size_t {
    const auto it =
        std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(label, size_t{0}));
    return it != sorted.end() && it->first == label ? it->second : 0;
  };
  std::vector<const SurfaceResult*> delivered;
  std::vector<Box> boxes;
  std::vector<size_t> layers;
  for (const auto& s : surfaces)
    if (s.is_output && !s.mesh.triangles.empty()) {
      delivered.push_back(&s);
      boxes.push_back(box_of(s.mesh));
      layers.push_back(layer(s.label));
    }
  std::vector<LabelsCrossing> found;
  for (size_t i = 0; i < delivered.size(); ++i) {
    const auto* s = delivered[i];
    if (s->stage == "net") continue;
    // Two labels made apart are tested once, from the first.
    std::vector<const SurfaceResult*> near;
    for (size_t j = 0; j < delivered.size(); ++j)
      if (j != i && delivered[j]->label != s->label && layers[j] == layers[i] &&
          boxes[i].meets(boxes[j]) && (j > i || delivered[j]->stage == "net"))
        near.push_back(delivered[j]);
    if (near.empty()) continue;
    for (const auto& [other, pairs] : crossings_with(*s, boxes[i], near))
      found.push_back({s->label, other, pairs});
  }
  return found;
}

}  // namespace labelmesh
