// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/surface/voxel_fidelity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/surface/surface_statistics.h"
#include "core/util/status_macros.h"
#include "core/util/vec3.h"
#include "core/volume/voxel_access.h"

namespace labelmesh::surface {
namespace {

using geometry::Vec3;

// The voxels of one label in a box around it: 1 inside the label.
struct LabelBox {
  std::array<int64_t, 3> lo{0, 0, 0};
  std::array<int64_t, 3> size{0, 0, 0};
  std::vector<uint8_t> inside;

  size_t at(int64_t i, int64_t j, int64_t k) const {
    return static_cast<size_t>(((k - lo[2]) * size[1] + (j - lo[1])) * size[0] + (i - lo[0]));
  }
  bool contains(int64_t i, int64_t j, int64_t k) const {
    return i >= lo[0] && j >= lo[1] && k >= lo[2] && i < lo[0] + size[0] && j < lo[1] + size[1] &&
           k < lo[2] + size[2];
  }
  bool label_at(int64_t i, int64_t j, int64_t k) const {
    return contains(i, j, k) && inside[at(i, j, k)] != 0;
  }
};

absl::StatusOr<LabelBox> label_box(const volume::LabelVolume& volume,
                                   const volume::LabelStatistics& label) {
  const auto& dims = volume.geometry.dims;
  LabelBox box;
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = std::max<int64_t>(0, label.min_index[a] - 1);
    box.size[a] = std::min<int64_t>(dims[a] - 1, label.max_index[a] + 1) - box.lo[a] + 1;
  }
  box.inside.assign(static_cast<size_t>(box.size[0] * box.size[1] * box.size[2]), 0);
  const bool typed = volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count != static_cast<size_t>(dims[0] * dims[1] * dims[2])) return;
    for (int64_t k = box.lo[2]; k < box.lo[2] + box.size[2]; ++k)
      for (int64_t j = box.lo[1]; j < box.lo[1] + box.size[1]; ++j) {
        const size_t row = static_cast<size_t>((k * dims[1] + j) * dims[0]);
        for (int64_t i = box.lo[0]; i < box.lo[0] + box.size[0]; ++i)
          box.inside[box.at(i, j, k)] =
              static_cast<int32_t>(voxels[row + static_cast<size_t>(i)]) == label.label;
      }
  });
  if (!typed) return absl::InvalidArgumentError("voxel fidelity: unsupported voxel type");
  return box;
}

// The sign of the edge function of (a, b) at q, as if q were moved by an
// infinitesimal (e, e^2): never zero, and exactly opposite for (b, a), so a
// column through a shared edge or point crosses exactly one of the triangles
// around it. Points are (i, j) in voxel index space.
int perturbed_side(const Vec3& a, const Vec3& b, double i, double j, double& value) {
  value = (b[0] - a[0]) * (j - a[1]) - (b[1] - a[1]) * (i - a[0]);
  if (value != 0) return value > 0 ? 1 : -1;
  if (b[1] != a[1]) return b[1] > a[1] ? -1 : 1;
  return b[0] > a[0] ? 1 : (b[0] < a[0] ? -1 : 0);
}

// The same with the edge taken from the lower point id, negated when the
// triangle runs it the other way.
int edge_side(const std::vector<Vec3>& at, uint32_t a, uint32_t b, double i, double j,
              double& value) {
  if (a < b) return perturbed_side(at[a], at[b], i, j, value);
  const int side = perturbed_side(at[b], at[a], i, j, value);
  value = -value;
  return -side;
}

// Where each column of voxel centres (i, j) along k crosses the surface.
struct Crossings {
  std::vector<uint32_t> start;  // per column, CSR offsets into k
  std::vector<double> k;
};

Crossings column_crossings(const std::vector<Vec3>& at,
                           const std::vector<std::array<uint32_t, 3>>& triangles,
                           const LabelBox& box) {
  const size_t columns = static_cast<size_t>(box.size[0] * box.size[1]);
  std::vector<std::pair<uint32_t, double>> hits;
  for (const auto& t : triangles) {
    const Vec3 &a = at[t[0]], &b = at[t[1]], &c = at[t[2]];
    const auto i0 = std::max<int64_t>(box.lo[0], int64_t(std::ceil(std::min({a[0], b[0], c[0]}))));
    const auto i1 = std::min<int64_t>(box.lo[0] + box.size[0] - 1,
                                      int64_t(std::floor(std::max({a[0], b[0], c[0]}))));
    const auto j0 = std::max<int64_t>(box.lo[1], int64_t(std::ceil(std::min({a[1], b[1], c[1]}))));
    const auto j1 = std::min<int64_t>(box.lo[1] + box.size[1] - 1,
                                      int64_t(std::floor(std::max({a[1], b[1], c[1]}))));
    for (int64_t j = j0; j <= j1; ++j) {
      for (int64_t i = i0; i <= i1; ++i) {
        double wa, wb, wc;
        const int sa = edge_side(at, t[1], t[2], double(i), double(j), wa);
        const int sb = edge_side(at, t[2], t[0], double(i), double(j), wb);
        const int sc = edge_side(at, t[0], t[1], double(i), double(j), wc);
        if (sa == 0 || sa != sb || sb != sc) continue;
        const double sum = wa + wb + wc;
        const double k =
            sum != 0 ? (wa * a[2] + wb * b[2] + wc * c[2]) / sum : (a[2] + b[2] + c[2]) / 3;
        hits.push_back({static_cast<uint32_t>((j - box.lo[1]) * box.size[0] + (i - box.lo[0])), k});
      }
    }
  }
  std::sort(hits.begin(), hits.end());
  Crossings crossings;
  crossings.start.assign(columns + 1, 0);
  crossings.k.reserve(hits.size());
  for (const auto& [column, k] : hits) {
    ++crossings.start[column + 1];
    crossings.k.push_back(k);
  }
  for (size_t c = 0; c < columns; ++c) crossings.start[c + 1] += crossings.start[c];
  return crossings;
}

// Distance from p to triangle (a, b, c) (Ericson, Real-Time Collision
// Detection, 5.1.5).
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  using namespace geometry;
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(ap);
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(sub(p, add(a, scale(ab, d1 / (d1 - d3)))));
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(sub(p, add(a, scale(ac, d2 / (d2 - d6)))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return norm(sub(p, add(b, scale(sub(c, b), w))));
  }
  const double denom = 1 / (va + vb + vc);
  const Vec3 closest = add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)));
  return norm(sub(p, closest));
}

// The distance from voxel centres to the surface, in index units, over the
// triangles near each: a bucket grid of one voxel cells.
class NearTriangles {
 public:
  // Over the index box from `lo`, `size` voxels along each axis.
  NearTriangles(const std::vector<Vec3>& at, const std::vector<std::array<uint32_t, 3>>& triangles,
                const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& size)
      : at_(at), triangles_(triangles), lo_(lo) {
    for (int a = 0; a < 3; ++a) size_[a] = size[a] + 2 * kMargin;
    std::vector<std::pair<size_t, uint32_t>> entries;
    for (uint32_t t = 0; t < triangles.size(); ++t) {
      std::array<int64_t, 3> lo{}, hi{};
      for (int a = 0; a < 3; ++a) {
        const double mn =
            std::min({at[triangles[t][0]][a], at[triangles[t][1]][a], at[triangles[t][2]][a]});
        const double mx =
            std::max({at[triangles[t][0]][a], at[triangles[t][1]][a], at[triangles[t][2]][a]});
        lo[a] = std::max<int64_t>(0, cell(mn, a));
        hi[a] = std::min<int64_t>(size_[a] - 1, cell(mx, a));
      }
      for (int64_t z = lo[2]; z <= hi[2]; ++z)
        for (int64_t y = lo[1]; y <= hi[1]; ++y)
          for (int64_t x = lo[0]; x <= hi[0]; ++x) entries.push_back({index(x, y, z), t});
    }
    std::sort(entries.begin(), entries.end());
    start_.assign(static_cast<size_t>(size_[0] * size_[1] * size_[2]) + 1, 0);
    for (const auto& [c, t] : entries) {
      ++start_[c + 1];
      ids_.push_back(t);
    }
    for (size_t c = 0; c + 1 < start_.size(); ++c) start_[c + 1] += start_[c];
  }

  // The distance to the nearest triangle within two cells; at least 2 when
  // none is that near. Cells are searched in rings outwards; the search stops
  // once the nearest found is within `enough` (the caller needs no more) or
  // nearer than any further ring can be.
  double distance(const Vec3& p, double enough = 0) const {
    double best = 2;
    std::array<int64_t, 3> c{};
    for (int a = 0; a < 3; ++a) c[a] = cell(p[a], a);
    for (int64_t ring = 0; ring <= 2; ++ring) {
      for (int64_t z = std::max<int64_t>(0, c[2] - ring); z <= std::min(size_[2] - 1, c[2] + ring);
           ++z)
        for (int64_t y = std::max<int64_t>(0, c[1] - ring);
             y <= std::min(size_[1] - 1, c[1] + ring); ++y)
          for (int64_t x = std::max<int64_t>(0, c[0] - ring);
               x <= std::min(size_[0] - 1, c[0] + ring); ++x) {
            const int64_t away =
                std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])});
            if (away != ring) continue;
            const size_t at = index(x, y, z);
            for (uint32_t i = start_[at]; i < start_[at + 1]; ++i) {
              const auto& t = triangles_[ids_[i]];
              best = std::min(best, point_triangle_distance(p, at_[t[0]], at_[t[1]], at_[t[2]]));
            }
          }
      if (best <= enough || best <= double(ring)) break;
    }
    return best;
  }

 private:
  static constexpr int64_t kMargin = 2;
  int64_t cell(double v, int a) const {
    return std::clamp<int64_t>(int64_t(std::floor(v)) - lo_[a] + kMargin, 0, size_[a] - 1);
  }
  size_t index(int64_t x, int64_t y, int64_t z) const {
    return static_cast<size_t>((z * size_[1] + y) * size_[0] + x);
  }
  const std::vector<Vec3>& at_;
  const std::vector<std::array<uint32_t, 3>>& triangles_;
  std::array<int64_t, 3> lo_{0, 0, 0};
  std::array<int64_t, 3> size_{0, 0, 0};
  std::vector<uint32_t> start_;
  std::vector<uint32_t> ids_;
};

std::vector<Vec3> index_points(const TriangleMesh& mesh, const volume::ImageGeometry& geometry) {
  std::vector<Vec3> at(mesh.points.size());
  for (size_t p = 0; p < at.size(); ++p) at[p] = geometry.to_index(mesh.points[p]);
  return at;
}

// The axis-aligned share with each triangle's normal from `facing`, given its
// own (unnormalised) normal and its LPS corners.
template <typename Facing>
double share_facing_axes(const TriangleMesh& mesh, const volume::ImageGeometry& geometry,
                         const Facing& facing) {
  const double cosine = std::cos(kAxisAlignedDeg * M_PI / 180);
  const auto& d = geometry.direction;
  // The voxel axes in LPS: the direction matrix's columns.
  const std::array<Vec3, 3> axes{Vec3{d[0], d[3], d[6]}, Vec3{d[1], d[4], d[7]},
                                 Vec3{d[2], d[5], d[8]}};
  const std::vector<Vec3> at = index_points(mesh, geometry);
  double aligned = 0, total = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const Vec3 centroid =
        geometry::scale(geometry::add(at[t[0]], geometry::add(at[t[1]], at[t[2]])), 1.0 / 3);
    bool cap = false;
    for (int k = 0; k < 3; ++k)
      cap = cap || centroid[k] < 0 || centroid[k] > double(geometry.dims[k] - 1);
    if (cap) continue;
    const Vec3 face = geometry::cross(geometry::sub(b, a), geometry::sub(c, a));
    const double twice_area = geometry::norm(face);
    if (twice_area == 0) continue;
    total += twice_area;
    const Vec3 normal = facing(face, a, b, c);
    const double length = geometry::norm(normal);
    if (length == 0) continue;
    for (const auto& axis : axes) {
      if (std::abs(geometry::dot(normal, axis)) >= cosine * length) {
        aligned += twice_area;
        break;
      }
    }
  }
  return total > 0 ? aligned / total : 0;
}

}  // namespace

double axis_aligned_share(const TriangleMesh& mesh, const volume::ImageGeometry& geometry) {
  return share_facing_axes(
      mesh, geometry, [](const Vec3& face, const Vec3&, const Vec3&, const Vec3&) { return face; });
}

double axis_aligned_share(const TriangleMesh& mesh, const volume::ImageGeometry& geometry,
                          const std::function<Vec3(const Vec3&)>& normal_at) {
  return share_facing_axes(
      mesh, geometry, [&](const Vec3&, const Vec3& a, const Vec3& b, const Vec3& c) {
        return normal_at(geometry::scale(geometry::add(a, geometry::add(b, c)), 1.0 / 3));
      });
}

double corresponding_hausdorff_voxels(const TriangleMesh& mesh, const TriangleMesh& staircase,
                                      const volume::ImageGeometry& geometry) {
  double largest = 0;
  for (size_t p = 0; p < mesh.points.size() && p < staircase.points.size(); ++p) {
    const Vec3 moved =
        geometry::sub(geometry.to_index(mesh.points[p]), geometry.to_index(staircase.points[p]));
    largest = std::max(largest, geometry::norm(moved));
  }
  return largest;
}

double sampled_hausdorff_voxels(const TriangleMesh& mesh, const TriangleMesh& staircase,
                                const volume::ImageGeometry& geometry, const RunContext& context) {
  const std::vector<Vec3> a = index_points(mesh, geometry);
  const std::vector<Vec3> b = index_points(staircase, geometry);
  // One box around both.
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto* points : {&a, &b})
    for (const auto& p : *points)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
      }
  if (a.empty() || b.empty()) return 0;
  std::array<int64_t, 3> first{}, size{};
  for (int k = 0; k < 3; ++k) {
    first[k] = int64_t(std::floor(lo[k]));
    size[k] = int64_t(std::floor(hi[k])) - first[k] + 1;
  }
  // The samples of one surface: its points and its triangles' centroids.
  const auto farthest = [&](const std::vector<Vec3>& from,
                            const std::vector<std::array<uint32_t, 3>>& from_triangles,
                            const NearTriangles& to) {
    double largest = 0;
    for (const auto& p : from) largest = std::max(largest, to.distance(p, largest));
    for (const auto& t : from_triangles) {
      if (context.stop_requested()) break;
      const Vec3 centroid = geometry::scale(
          geometry::add(from[t[0]], geometry::add(from[t[1]], from[t[2]])), 1.0 / 3);
      largest = std::max(largest, to.distance(centroid, largest));
    }
    return largest;
  };
  const NearTriangles near_b(b, staircase.triangles, first, size);
  const NearTriangles near_a(a, mesh.triangles, first, size);
  return std::max(farthest(a, mesh.triangles, near_b), farthest(b, staircase.triangles, near_a));
}

absl::StatusOr<VoxelFidelity> measure_voxel_fidelity(const TriangleMesh& mesh,
                                                     const volume::LabelVolume& volume,
                                                     const volume::LabelStatistics& label,
                                                     const RunContext& context) {
  const auto& geometry = volume.geometry;
  VoxelFidelity fidelity;
  fidelity.voxel_volume_mm3 = double(label.voxels) * geometry.voxel_volume();
  if (fidelity.voxel_volume_mm3 > 0)
    fidelity.volume_change = signed_volume(mesh) / fidelity.voxel_volume_mm3 - 1;
  fidelity.axis_aligned_share = axis_aligned_share(mesh, geometry);

  LABELMESH_ASSIGN_OR_RETURN(auto box, label_box(volume, label));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  const std::vector<Vec3> at = index_points(mesh, geometry);
  const Crossings crossings = column_crossings(at, mesh.triangles, box);
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  std::vector<Vec3> wrong;
  const auto& b = box;
  const auto& dims = geometry.dims;
  for (int64_t j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j) {
    for (int64_t i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
      const size_t column = static_cast<size_t>((j - b.lo[1]) * b.size[0] + (i - b.lo[0]));
      const double* first = crossings.k.data() + crossings.start[column];
      const double* last = crossings.k.data() + crossings.start[column + 1];
      for (int64_t k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k) {
        const bool in = b.inside[b.at(i, j, k)] != 0;
        // A face neighbour on the other side (the volume's outside counts as
        // not the label).
        bool boundary = false;
        constexpr int kSteps[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        for (const auto& s : kSteps) {
          const int64_t x = i + s[0], y = j + s[1], z = k + s[2];
          const bool outside_volume =
              x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2];
          const bool neighbour_in = !outside_volume && b.label_at(x, y, z);
          if (neighbour_in != in) {
            boundary = true;
            break;
          }
        }
        if (!boundary) continue;
        if (in) ++fidelity.boundary_voxels;
        const auto below = std::count_if(first, last, [k](double z) { return z < double(k); });
        const bool surface_in = below % 2 == 1;
        if (surface_in != in) wrong.push_back({double(i), double(j), double(k)});
      }
    }
  }
  fidelity.misclassified = wrong.size();
  if (!wrong.empty()) {
    const NearTriangles near(at, mesh.triangles, b.lo, b.size);
    for (const auto& centre : wrong)
      fidelity.farthest_misclassified_voxels =
          std::max(fidelity.farthest_misclassified_voxels, near.distance(centre));
  }
  return fidelity;
}

}  // namespace labelmesh::surface
