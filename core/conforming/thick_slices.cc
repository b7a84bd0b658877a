// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/conforming/thick_slices.h"

#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/voxel_access.h"
#include "core/volume/voxel_box.h"

namespace labelmesh::conforming {
namespace {

constexpr float kFar = std::numeric_limits<float>::max();
// Rounds of tuning each label's bias to its volume, and how near the volume
// is near enough. The bias swells a label's walls between slices and not on
// them, so it bends them: a label the interpolation keeps within 1 % of its
// volume keeps its walls as interpolated (on 1 x 1 x 3 mm slices a sphere's
// normals' 95th percentile is 7.9 degrees so, 9.8 biased to 0.1 %).
constexpr int kBiasRounds = 6;
constexpr double kBiasTolerance = 0.01;
// The signed distances' clamp, in slices.
constexpr float kBandSlices = 2;
// The largest bias, in slices: below the distances' clamp, so that half
// way between slices the interpolated distances still shape a biased label.
constexpr double kMostBiasSlices = 1.5;
static_assert(kMostBiasSlices < kBandSlices);
// Slice distances kept between rounds: at most 256 MiB of them.
constexpr size_t kCacheFloats = size_t{64} << 20;

// Squared distance transform along one line (the lower envelope of
// parabolas, Felzenszwalb and Huttenlocher): f holds squared distances so far
// (kFar where none), `step` the spacing in mm; the result replaces f.
void distance_along_line(std::vector<float>& f, double step, std::vector<float>& out,
                         std::vector<int>& apex, std::vector<double>& bound) {
  const int n = static_cast<int>(f.size());
  const double s2 = step * step;
  const auto meet = [&](int q, int p) {
    return ((f[q] + s2 * q * q) - (f[p] + s2 * p * p)) / (2 * s2 * (q - p));
  };
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    if (k < 0) {
      k = 0;
      apex[0] = q;
      bound[0] = -std::numeric_limits<double>::infinity();
      bound[1] = std::numeric_limits<double>::infinity();
      continue;
    }
    double s = meet(q, apex[k]);
    while (s <= bound[k]) s = meet(q, apex[--k]);
    ++k;
    apex[k] = q;
    bound[k] = s;
    bound[k + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0) return;
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (bound[k + 1] < q) ++k;
    const double d = step * (q - apex[k]);
    out[q] = static_cast<float>(d * d + f[apex[k]]);
  }
  std::copy(out.begin(), out.begin() + n, f.begin());
}

// Euclidean distance (mm) from every pixel of a slice (nu x nv, spacing su,
// sv) to the nearest pixel where `inside` is true; kFar where none is.
std::vector<float> distance_to(const std::vector<uint8_t>& inside, int64_t nu, int64_t nv,
                               double su, double sv) {
  std::vector<float> d(inside.size());
  for (size_t i = 0; i < inside.size(); ++i) d[i] = inside[i] ? 0.f : kFar;
  const int64_t longest = std::max(nu, nv);
  std::vector<float> line(longest), out(longest);
  std::vector<int> apex(longest);
  std::vector<double> bound(longest + 1);
  for (int64_t v = 0; v < nv; ++v) {
    line.assign(d.begin() + v * nu, d.begin() + (v + 1) * nu);
    out.resize(nu);
    distance_along_line(line, su, out, apex, bound);
    std::copy(line.begin(), line.end(), d.begin() + v * nu);
  }
  line.resize(nv);
  out.resize(nv);
  for (int64_t u = 0; u < nu; ++u) {
    for (int64_t v = 0; v < nv; ++v) line[v] = d[v * nu + u];
    distance_along_line(line, sv, out, apex, bound);
    for (int64_t v = 0; v < nv; ++v) d[v * nu + u] = line[v];
  }
  for (float& x : d) x = x >= kFar ? kFar : std::sqrt(x);
  return d;
}

// The box the interpolation covers around the selected labels' `box`: two
// slices more along the cut axis (the cubic reads two on either side), and
// in the slices the distances' clamp and two voxels more: every pixel
// within the clamp of a label is then in it, so each label's clamped
// distance is the whole volume's (a margin of a voxel or two would do
// nearly as well, at a fraction of a pixel's error where a label's nearest
// outside pixel lies beyond it). A thin voxel takes only labels drawn at
// its pixel, so outside it every thinner voxel is 0, as it would be from
// the whole volume. With no label, a voxel's box.
struct CoveredBox {
  std::array<int64_t, 3> lo{0, 0, 0}, dims{0, 0, 0};
};
CoveredBox covered_box(volume::VoxelBox box, const volume::ImageGeometry& geometry, int axis) {
  if (box.empty()) box.last = box.first;
  const double band = kBandSlices * geometry.spacing[axis];
  CoveredBox covered;
  for (int k = 0; k < 3; ++k) {
    const auto margin =
        k == axis ? int64_t{2} : static_cast<int64_t>(std::ceil(band / geometry.spacing[k])) + 2;
    covered.lo[k] = std::max<int64_t>(0, box.first[k] - margin);
    covered.dims[k] = std::min(geometry.dims[k] - 1, box.last[k] + margin) - covered.lo[k] + 1;
  }
  return covered;
}

// Whether `voxel` holds one of `selected` (sorted; every non-zero label
// when empty): its label if so, else 0.
template <typename T>
int32_t selected_label(T voxel, const std::vector<int32_t>& selected) {
  const auto label = static_cast<int32_t>(voxel);
  return label != 0 &&
                 (selected.empty() || std::binary_search(selected.begin(), selected.end(), label))
             ? label
             : 0;
}

// The box the interpolation covers for `selected` (sorted) along `axis`. A
// scalar array shorter than the grid (readers refuse those) counts as empty.
CoveredBox selected_box(const volume::LabelVolume& volume, const std::vector<int32_t>& selected,
                        int axis) {
  volume::VoxelBox box;
  const auto& dims = volume.geometry.dims;
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count < static_cast<size_t>(volume.geometry.voxel_count())) return;
    box = volume::voxel_box(voxels, dims, [&](auto v) { return selected_label(v, selected) != 0; });
  });
  return covered_box(box, volume.geometry, axis);
}

// The labels of `volume` in the box the interpolation covers (cut along
// `axis`), x fastest: `selected` ones (every non-zero one when empty), the
// others 0. Beyond the box every voxel is 0.
struct BoxLabels {
  CoveredBox box;
  std::vector<int32_t> labels;
};
BoxLabels selected_in_box(const volume::LabelVolume& volume, std::vector<int32_t> selected,
                          int axis) {
  std::sort(selected.begin(), selected.end());
  BoxLabels out;
  out.box = selected_box(volume, selected, axis);
  const auto& lo = out.box.lo;
  const auto& d = out.box.dims;
  const auto& dims = volume.geometry.dims;
  out.labels.assign(static_cast<size_t>(d[0] * d[1] * d[2]), 0);
  volume::visit_voxels(volume.voxels, [&](const auto* voxels, size_t count) {
    if (count < static_cast<size_t>(volume.geometry.voxel_count())) return;
    size_t o = 0;
    for (int64_t z = lo[2]; z < lo[2] + d[2]; ++z)
      for (int64_t y = lo[1]; y < lo[1] + d[1]; ++y)
        for (int64_t x = lo[0]; x < lo[0] + d[0]; ++x)
          out.labels[o++] = selected_label(
              voxels[static_cast<size_t>((z * dims[1] + y) * dims[0] + x)], selected);
  });
  return out;
}

// The weights of four slices at -1, 0, 1 and 2 for a place t (0 to 1) between
// the middle two: a Catmull-Rom cubic (Catmull and Rom, "A class of local
// interpolating splines", 1974), which passes through each slice and bends
// smoothly from one to the next. Linear weights cut a thin shape's distances
// down between its slices, as a chord lies below its curve, and so thin
// rings on thick slices; the cubic follows the curve.
std::array<double, 4> catmull_rom_weights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {0.5 * (-t3 + 2 * t2 - t), 0.5 * (3 * t3 - 5 * t2 + 2), 0.5 * (-3 * t3 + 4 * t2 + t),
          0.5 * (t3 - t2)};
}

// Where thin slice j's centre lies along the cut axis, in thick slices (0 at
// the first thick slice's centre), with `parts` thin slices to a thick one.
double thick_place(int64_t j, int parts) { return (double(j) + 0.5) / parts - 0.5; }

// How much of a label's bias acts on a thin slice at place t (0 to 1)
// between two drawn slices: none on them, all of it half way.
double bias_taper(double t) { return 4 * t * (1 - t); }

// The thinner grid's labels from the thick slices' signed distances, each
// label's shifted by a bias (mm) that the caller tunes to keep its volume.
class SliceInterpolator {
 public:
  SliceInterpolator(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                    const ThickSlices& cut)
      : geometry_(volume.geometry),
        cut_(cut),
        a_(cut.axis),
        u_((cut.axis + 1) % 3),
        v_((cut.axis + 2) % 3),
        // Clamped to two slices' thickness. Where a label fills a slice
        // or is absent from it, the next slice's shape still takes over half
        // way between them, where the voxels say it does. Below the clamp
        // the crossing follows the distances: a clamp of one slice flattened
        // every wall leaning more than 45 degrees from the axis (its contour
        // moves more than a slice's thickness from slice to slice) into
        // terraces half way, and a label's last slice into a plateau with a
        // step at its rim.
        band_(static_cast<float>(kBandSlices * volume.geometry.spacing[cut.axis])),
        // The contour runs between pixel centres, half a pixel from each
        // (half the smaller spacing where pixels are not square): distances
        // between centres less this are distances to the contour. Without
        // it no distance would lie within half a pixel of the contour, and
        // between slices a wall would stay on each slice's contour for that
        // much before moving on, a stair of the thick slices in its slope.
        edge_(static_cast<float>(0.5 * std::min(volume.geometry.spacing[(cut.axis + 1) % 3],
                                                volume.geometry.spacing[(cut.axis + 2) % 3]))) {
    const auto in_box = selected_in_box(volume, labels, a_);
    lo_ = in_box.box.lo;
    dims_ = in_box.box.dims;
    present_ = in_box.labels;
    // Beyond a box smaller than the volume every voxel is 0.
    if (dims_ != geometry_.dims) present_.push_back(0);
    std::sort(present_.begin(), present_.end());
    present_.erase(std::unique(present_.begin(), present_.end()), present_.end());
    source_slots_.reserve(in_box.labels.size());
    for (const int32_t label : in_box.labels)
      source_slots_.push_back(static_cast<uint32_t>(at(label)));
    cache_.resize(static_cast<size_t>(dims_[a_]));
  }

  const std::vector<int32_t>& present() const { return present_; }
  // The box covered, on the drawn grid.
  const std::array<int64_t, 3>& box_first() const { return lo_; }
  const std::array<int64_t, 3>& box_dims() const { return dims_; }

  // The bias taper's mean over the thin slices of one thick slice. Beyond
  // the first and last slice centres the fill's place is clamped there and
  // the taper is 0, so on volumes of few slices the true mean is lower and
  // the bias rounds step short (the best of the rounds is kept).
  double mean_taper() const {
    double sum = 0;
    for (int j = 0; j < cut_.parts; ++j) {
      const double position = thick_place(j, cut_.parts);
      sum += bias_taper(position - std::floor(position));
    }
    return sum / cut_.parts;
  }

  // Voxels of each present label in the thick slices.
  std::vector<uint64_t> source_counts() const {
    std::vector<uint64_t> counts(present_.size(), 0);
    for (const uint32_t slot : source_slots_) ++counts[slot];
    add_outside_box(counts, 1);
    return counts;
  }

  // Fills `out` (the covered box on the thinner grid, x fastest) with
  // `bias[l]` added to label l's distances; returns each label's voxels and
  // how many of them touch another label across a face.
  void fill(const std::vector<double>& bias, int32_t* out, std::vector<uint64_t>& counts,
            std::vector<uint64_t>& boundary) const {
    const int64_t na = geometry_.dims[a_], nu = dims_[u_], nv = dims_[v_];
    // The box on the thinner grid: where its first thin slice lies, and its
    // size, which `out` has.
    std::array<int64_t, 3> fine_lo = lo_, fine_box = dims_;
    fine_lo[a_] *= cut_.parts;
    fine_box[a_] *= cut_.parts;
    const std::array<int64_t, 3> stride{1, fine_box[0], fine_box[0] * fine_box[1]};
    // The four slices around each thin one: before, below, above, after.
    // Slices beyond the box hold no selected label, as its edge slices do.
    int64_t held = -1;
    std::array<std::shared_ptr<const Distances>, 4> around;
    for (int64_t j = 0; j < fine_box[a_]; ++j) {
      const double position =
          std::clamp(thick_place(fine_lo[a_] + j, cut_.parts), 0.0, double(na - 1));
      const int64_t i = std::min(static_cast<int64_t>(position), na - 2);
      const double t = position - i;
      // Slice i - 1 + k of the volume as a slice of the box (k = 0 to 3:
      // before, below, above, after); the box's end slices stand in beyond.
      const auto slice = [&](int k) {
        return std::clamp<int64_t>(i - 1 + k, lo_[a_], lo_[a_] + dims_[a_] - 1) - lo_[a_];
      };
      if (held != i) {
        // At the box's ends a slice stands in for its missing neighbour:
        // the same distances, computed once even when the cache is full.
        const auto take = [&](int k) {
          around[k] = k > 0 && slice(k) == slice(k - 1) ? around[k - 1] : distances(slice(k));
        };
        if (held >= 0 && held == i - 1) {
          std::rotate(around.begin(), around.begin() + 1, around.end());
          take(3);
        } else {
          for (int k = 0; k < 4; ++k) take(k);
        }
        held = i;
      }
      const auto weight = catmull_rom_weights(t);
      // The bias acts between the drawn slices, not on them: their voxels
      // are data, where the volume error comes from the guess between.
      const double taper = bias_taper(t);
      const int64_t below = slice(1), above = slice(2);
      for (int64_t pv = 0; pv < nv; ++pv) {
        for (int64_t pu = 0; pu < nu; ++pu) {
          const size_t p = static_cast<size_t>(pv * nu + pu);
          // A thin voxel takes the label of one of the two drawn voxels
          // around it, whichever's distance is the larger there: the cubic
          // may overshoot, and labels compete, but no label reaches a pixel
          // that neither drawn slice gives it.
          const std::array<size_t, 2> candidates{source_slots_[index(below, pu, pv)],
                                                 source_slots_[index(above, pu, pv)]};
          size_t best = candidates[0];
          double best_value = -std::numeric_limits<double>::infinity();
          for (const size_t l : candidates) {
            double value = taper * bias[l];
            for (int k = 0; k < 4; ++k) value += weight[k] * (*around[k])[l][p];
            if (value > best_value) {
              best_value = value;
              best = l;
            }
          }
          out[j * stride[a_] + pu * stride[u_] + pv * stride[v_]] = present_[best];
        }
      }
    }
    counts.assign(present_.size(), 0);
    boundary.assign(present_.size(), 0);
    add_outside_box(counts, cut_.parts);
    // Only 0 lies at the box's faces, but where they are the volume's own.
    for (int64_t z = 0; z < fine_box[2]; ++z) {
      for (int64_t y = 0; y < fine_box[1]; ++y) {
        for (int64_t x = 0; x < fine_box[0]; ++x) {
          const int64_t i = x + y * stride[1] + z * stride[2];
          const size_t l = at(out[i]);
          ++counts[l];
          const bool touches = (x > 0 && out[i - 1] != out[i]) ||
                               (x + 1 < fine_box[0] && out[i + 1] != out[i]) ||
                               (y > 0 && out[i - stride[1]] != out[i]) ||
                               (y + 1 < fine_box[1] && out[i + stride[1]] != out[i]) ||
                               (z > 0 && out[i - stride[2]] != out[i]) ||
                               (z + 1 < fine_box[2] && out[i + stride[2]] != out[i]);
          boundary[l] += touches;
        }
      }
    }
  }

 private:
  size_t at(int32_t label) const {
    return static_cast<size_t>(std::lower_bound(present_.begin(), present_.end(), label) -
                               present_.begin());
  }

  // Adds the voxels outside the box, `parts` per thick one, to label 0's
  // count (where 0 is present).
  void add_outside_box(std::vector<uint64_t>& counts, int parts) const {
    const auto outside = static_cast<uint64_t>(
        geometry_.dims[0] * geometry_.dims[1] * geometry_.dims[2] - dims_[0] * dims_[1] * dims_[2]);
    const size_t zero = at(0);
    if (outside > 0 && zero < present_.size() && present_[zero] == 0)
      counts[zero] += outside * static_cast<uint64_t>(parts);
  }

  size_t index(int64_t i, int64_t pu, int64_t pv) const {
    const int64_t sx = 1, sy = dims_[0], sz = dims_[0] * dims_[1];
    const std::array<int64_t, 3> stride{sx, sy, sz};
    return static_cast<size_t>(i * stride[a_] + pu * stride[u_] + pv * stride[v_]);
  }

  using Distances = std::vector<std::vector<float>>;

  // Slice i's distances, kept for the next fill when they fit the cache.
  std::shared_ptr<const Distances> distances(int64_t i) const {
    if (cache_[i]) return cache_[i];
    auto computed = std::make_shared<const Distances>(slice_distances(i));
    if (cached_floats_ + present_.size() * slice_size() <= kCacheFloats) {
      cached_floats_ += present_.size() * slice_size();
      cache_[i] = computed;
    }
    return computed;
  }

  size_t slice_size() const { return static_cast<size_t>(dims_[u_] * dims_[v_]); }

  // Signed distance (mm, positive inside, within +-band) of each present
  // label in slice i.
  Distances slice_distances(int64_t i) const {
    const int64_t nu = dims_[u_], nv = dims_[v_];
    const double su = geometry_.spacing[u_], sv = geometry_.spacing[v_];
    std::vector<std::vector<float>> distances;
    std::vector<uint8_t> inside(static_cast<size_t>(nu * nv)), outside(inside.size());
    for (uint32_t slot = 0; slot < present_.size(); ++slot) {
      bool any = false;
      for (int64_t pv = 0; pv < nv; ++pv) {
        for (int64_t pu = 0; pu < nu; ++pu) {
          const bool in = source_slots_[index(i, pu, pv)] == slot;
          inside[pv * nu + pu] = in;
          outside[pv * nu + pu] = !in;
          any |= in;
        }
      }
      if (!any) {
        distances.emplace_back(inside.size(), -band_);
        continue;
      }
      const auto to_inside = distance_to(inside, nu, nv, su, sv);
      const auto to_outside = distance_to(outside, nu, nv, su, sv);
      std::vector<float> d(inside.size());
      for (size_t p = 0; p < d.size(); ++p) {
        d[p] = inside[p] ? std::min(to_outside[p] - edge_, band_)
                         : -std::min(to_inside[p] - edge_, band_);
      }
      distances.push_back(std::move(d));
    }
    return distances;
  }

  const volume::ImageGeometry& geometry_;
  const ThickSlices cut_;
  const int a_, u_, v_;
  const float band_;
  const float edge_;
  // The box covered (selected_in_box), and each of its voxels'
  // label as its place in present_, so the fill weighs labels by place.
  std::array<int64_t, 3> lo_{0, 0, 0}, dims_{0, 0, 0};
  std::vector<uint32_t> source_slots_;
  std::vector<int32_t> present_;
  mutable std::vector<std::shared_ptr<const Distances>> cache_;
  mutable size_t cached_floats_ = 0;
};

}  // namespace

ThickSlices find_thick_slices(const volume::ImageGeometry& geometry,
                              const ThickSliceParams& params) {
  const auto& s = geometry.spacing;
  const int axis = static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin());
  const double others = std::max(s[(axis + 1) % 3], s[(axis + 2) % 3]);
  if (!(others > 0) || s[axis] < params.min_ratio * others || geometry.dims[axis] < 2) return {};
  // No more thin voxels than a volume may hold.
  const int64_t voxels = std::max<int64_t>(1, geometry.voxel_count());
  const auto fitting =
      static_cast<int>(std::min<int64_t>(params.max_parts, params.max_voxels / voxels));
  const int parts = std::min(
      fitting, std::max(2, static_cast<int>(std::lround(s[axis] / (params.thin_ratio * others)))));
  return parts >= 2 ? ThickSlices{axis, parts} : ThickSlices{};
}

ThickSlices find_thick_slices(const volume::LabelVolume& volume, const std::vector<int32_t>& labels,
                              const ThickSliceParams& params) {
  ThickSliceParams uncapped = params;
  uncapped.max_voxels = std::numeric_limits<int64_t>::max();
  const ThickSlices axis = find_thick_slices(volume.geometry, uncapped);
  if (axis.axis < 0) return {};
  auto selected = labels;
  std::sort(selected.begin(), selected.end());
  volume::ImageGeometry covered = volume.geometry;
  covered.dims = selected_box(volume, selected, axis.axis).dims;
  return find_thick_slices(covered, params);
}

absl::StatusOr<volume::LabelVolume> interpolate_thick_slices(const volume::LabelVolume& volume,
                                                             const std::vector<int32_t>& labels,
                                                             const ThickSlices& cut,
                                                             const RunContext& context) {
  const auto& geometry = volume.geometry;
  if (cut.axis < 0 || cut.axis > 2 || cut.parts < 2 || geometry.dims[cut.axis] < 2) {
    return absl::InvalidArgumentError(
        cat("thick slices: cannot cut axis ", cut.axis, " into ", cut.parts, " parts"));
  }
  const SliceInterpolator interpolator(volume, labels, cut);
  // The thinner grid covers the labels' box (covered_box): the same
  // directions, `cut.parts` slices for each drawn one.
  volume::LabelVolume fine;
  fine.format = volume.format;
  fine.file_voxel_type = volume.file_voxel_type;
  fine.descriptions = volume.descriptions;
  fine.geometry = geometry;
  fine.geometry.dims = interpolator.box_dims();
  fine.geometry.dims[cut.axis] *= cut.parts;
  fine.geometry.spacing[cut.axis] /= cut.parts;
  std::array<double, 3> first{0, 0, 0};
  for (int k = 0; k < 3; ++k) first[k] = double(interpolator.box_first()[k]);
  first[cut.axis] += -0.5 + 0.5 / cut.parts;
  fine.geometry.origin = geometry.to_physical(first);
  fine.voxels = vtkSmartPointer<vtkImageData>::New();
  fine.voxels->SetDimensions(static_cast<int>(fine.geometry.dims[0]),
                             static_cast<int>(fine.geometry.dims[1]),
                             static_cast<int>(fine.geometry.dims[2]));
  fine.voxels->AllocateScalars(VTK_INT, 1);
  auto* out = static_cast<int32_t*>(fine.voxels->GetScalarPointer());
  if (out == nullptr) {
    return absl::ResourceExhaustedError(
        cat("thick slices: no memory for ", fine.geometry.voxel_count(), " thinner voxels"));
  }

  // Interpolation thins narrow shapes; each label's bias is raised by its
  // missing volume spread over its boundary (by half a band for a label that
  // vanished, which has none) and over the thin slices' mean taper, at most
  // half a band a round and kMostBiasSlices bands in all, until every label
  // has its voxels' volume to within kBiasTolerance or the rounds run out;
  // the best round's biases are kept. The band here is one slice's
  // thickness: a tube whose last drawn slices just hold it rounds off a
  // whole slice short of the next, and takes more than a band to get its
  // volume back.
  const auto& present = interpolator.present();
  std::vector<uint64_t> target = interpolator.source_counts();
  for (auto& count : target) count *= cut.parts;
  const double step =
      std::cbrt(fine.geometry.spacing[0] * fine.geometry.spacing[1] * fine.geometry.spacing[2]);
  const double band = geometry.spacing[cut.axis];
  const double taper = interpolator.mean_taper();
  std::vector<double> bias(present.size(), 0), best_bias;
  struct Tried {
    bool tried = false;
    double bias = 0;
    uint64_t count = 0;
  };
  std::vector<Tried> short_of(present.size()), past(present.size());
  std::vector<double> last_bias(present.size(), 0);
  std::vector<uint64_t> last_counts(present.size(), 0);
  double best_error = std::numeric_limits<double>::infinity();
  std::vector<uint64_t> counts, boundary;
  for (int round = 0;; ++round) {
    LABELMESH_RETURN_IF_ERROR(context.check_stop());
    interpolator.fill(bias, out, counts, boundary);
    double error = 0;
    for (size_t l = 0; l < present.size(); ++l) {
      error = std::max(error, std::abs(double(target[l]) - double(counts[l])) /
                                  std::max(1.0, double(target[l])));
    }
    const bool best = error < best_error;
    if (best) {
      best_error = error;
      best_bias = bias;
    }
    if (error <= kBiasTolerance || round == kBiasRounds) {
      if (!best) interpolator.fill(best_bias, out, counts, boundary);
      break;
    }
    for (size_t l = 0; l < present.size(); ++l) {
      const double missing = double(target[l]) - double(counts[l]);
      double change = boundary[l] > 0 ? missing * step / (taper * double(boundary[l]))
                      : missing > 0   ? band / 2
                                      : 0;
      // The estimate above undershoots where the bias acts on few thin
      // slices: after a first round, the voxels a millimetre of bias gained
      // there say how far to go; once biases short of the volume and past
      // it are known, the next lies between the nearest two, where a
      // straight line through them meets the volume (thin voxels flip ring
      // by ring, and a line through the last two may overshoot).
      Tried& under = short_of[l];
      Tried& over = past[l];
      if (missing > 0 && (!under.tried || bias[l] > under.bias)) under = {true, bias[l], counts[l]};
      if (missing < 0 && (!over.tried || bias[l] < over.bias)) over = {true, bias[l], counts[l]};
      if (round > 0 && bias[l] != last_bias[l] && counts[l] != last_counts[l]) {
        const double gained =
            (double(counts[l]) - double(last_counts[l])) / (bias[l] - last_bias[l]);
        if (gained > 0) change = missing / gained;
      }
      last_bias[l] = bias[l];
      last_counts[l] = counts[l];
      if (missing != 0 && under.tried && over.tried && over.count > under.count) {
        change = under.bias - bias[l] +
                 (over.bias - under.bias) * (double(target[l]) - double(under.count)) /
                     (double(over.count) - double(under.count));
      }
      // A label within the tolerance keeps its bias (none, unless its
      // neighbours' biases pushed it out before): the bias bends walls.
      // The outside is always within it, counted against the whole box.
      if (std::abs(missing) <= kBiasTolerance * std::max(1.0, double(target[l]))) continue;
      bias[l] = std::clamp(bias[l] + std::clamp(change, -band / 2, band / 2),
                           -kMostBiasSlices * band, kMostBiasSlices * band);
    }
  }
  return fine;
}

}  // namespace labelmesh::conforming
