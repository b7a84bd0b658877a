// SPDX-License-Identifier: AGPL-3.0-or-later
// Smooth surfaces beside a Slicer-like VTK pipeline (tests/support/slicer_like.h),
// in one run:
//   phantoms   analytic shapes on coarse, anisotropic and oblique grids: RMS
//              distance and 95th-percentile normal error against the true
//              surface, for Marching Cubes, the Slicer-like surface and ours;
//   volumes    every shared multi-label volume: the time of all labels'
//              surfaces (both pipelines alternating, from reading the file),
//              the axis-aligned area share per label (median), and how many
//              labels each pipeline keeps within the voxel tolerance.
//   alignments the phantoms with their slices shifted by quarters of a slice:
//              each method's error averaged over the shifts, and its worst;
//   blurs      each label's mask blurred by Gaussians of growing width: the
//              axis-aligned share their surfaces reach against the boundary
//              voxel centres they put on the wrong side (not in "all");
//   shares     the phantoms' axis-aligned area share beside the true shape's;
//   slices     five touching labels on three 5 mm slices of 512 x 512 pixels,
//              as a DICOM SEG of a short series holds them, timed as the
//              volumes are (the file is written to the temporary directory).
// Usage: labelmesh_surface_bench
//          [phantoms|alignments|shares|volumes|slices|blurs|all] [ROUNDS] [FILE ...]
#if __has_include(<malloc.h>)
#include <malloc.h>
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench_inputs.h"
#include "bench/blur_bench.h"
#include "core/conforming/label_interfaces.h"
#include "core/conforming/net_label_surface.h"
#include "core/pipeline/label_net_surfaces.h"
#include "core/pipeline/pipeline.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/voxel_fidelity.h"
#include "core/surface/write_surface.h"
#include "core/util/side_by_side.h"
#include "core/volume/drawn_grid.h"
#include "core/volume/label_statistics.h"
#include "core/volume/read_label_volume.h"
#include "core/volume/write_label_volume.h"
#include "support/analytic_shapes.h"
#include "support/label_overlap.h"
#include "support/organs_on_slices.h"
#include "support/rim_turns.h"
#include "support/sharp_points.h"
#include "support/slicer_like.h"

using namespace labelmesh;
using namespace labelmesh::bench;
using labelmesh::testing::AnalyticShape;

namespace {

// Each timed run starts with the heap's free pages handed back to the
// system, as in a fresh process: otherwise a run is faster or slower by the
// pages the run before it left behind (a fresh page costs microseconds).
double seconds_of(const std::function<void()>& f) {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Our delivered surface of label 1, and its method.
surface::TriangleMesh our_surface(const volume::LabelVolume& volume, std::string& method) {
  auto result = run_pipeline_on_volume(volume, our_params(), RunContext{});
  if (!result.ok()) {
    std::printf("  ours failed: %s\n", std::string(result.status().message()).c_str());
    return {};
  }
  for (auto& s : result->surfaces)
    if (s.is_output && s.label == 1) {
      method = s.stage;
      return std::move(s.mesh);
    }
  return {};
}

// A grid the phantoms are sampled on; `degrees` turns its axes about (1, 1, 1).
struct Grid {
  const char* name;
  std::array<double, 3> spacing;
  double degrees;
  double shift_slices = 0;  // sample_shape's
};

// Label 1 of a phantom by Marching Cubes, the Slicer-like pipeline and ours.
struct PhantomSurfaces {
  volume::LabelVolume volume;
  surface::TriangleMesh marching_cubes;
  surface::TriangleMesh slicer;
  surface::TriangleMesh ours;
  std::string method;  // the stage ours was delivered by
};

std::optional<PhantomSurfaces> phantom_surfaces(const AnalyticShape& shape, const Grid& grid) {
  PhantomSurfaces made;
  made.volume = testing::sample_shape(shape, grid.spacing, grid.degrees, grid.shift_slices);
  const auto statistics = volume::compute_label_statistics(made.volume);
  auto mc = surface::extract_surfaces(made.volume, statistics, {1}, RunContext{});
  auto slicer = testing::slicer_like_surfaces(made.volume, statistics, {1});
  made.ours = our_surface(made.volume, made.method);
  if (!mc.ok() || mc->empty() || slicer.empty() || made.ours.triangles.empty()) return std::nullopt;
  made.marching_cubes = std::move(mc->front().mesh);
  made.slicer = std::move(slicer.front().mesh);
  return made;
}

// Where LABELMESH_BENCH_OUT=`out` keeps a phantom's files: its shape and
// grid, spaces as underscores.
std::string phantom_stem(const char* out, const AnalyticShape& shape, const Grid& grid) {
  std::string name = shape.name + "-" + grid.name;
  std::replace(name.begin(), name.end(), ' ', '_');
  return std::string(out) + "/" + name;
}

// The shapes the phantom tables measure.
std::vector<AnalyticShape> phantom_shapes() {
  return {testing::sphere_shape(25), testing::ellipsoid_shape(32, 22, 15),
          testing::torus_shape(25, 9), testing::torus_shape(25, 4.5, "thin tube")};
}

int bench_phantoms() {
  const std::vector<Grid> grids{{"3 mm", {3, 3, 3}, 0},
                                {"1x1x3 mm", {1, 1, 3}, 0},
                                {"0.6x0.6x4 mm", {0.6, 0.6, 4}, 0},
                                {"1x1x3 mm oblique", {1, 1, 3}, 25},
                                // The ellipsoid's poles and the torus's top lie on slice
                                // centres above; here they end between two slices.
                                {"3 mm, half up", {3, 3, 3}, 0, 0.5},
                                {"1x1x3 mm, half up", {1, 1, 3}, 0, 0.5},
                                {"0.6x0.6x4 half up", {0.6, 0.6, 4}, 0, 0.5}};
  const std::vector<AnalyticShape> shapes = phantom_shapes();
  std::printf("%-10s %-18s | %-22s | %-22s | %-22s | %s\n", "shape", "grid", "MC rms mm / p95 deg",
              "Slicer-like", "ours", "ours / smallest spacing, method");
  int failures = 0;
  for (const auto& grid : grids) {
    const double smallest = *std::min_element(grid.spacing.begin(), grid.spacing.end());
    for (const auto& shape : shapes) {
      const auto made = phantom_surfaces(shape, grid);
      if (!made) {
        ++failures;
        continue;
      }
      // LABELMESH_BENCH_OUT=DIR keeps the three surfaces as STL, to look at,
      // and the phantom's volume, to mesh again.
      if (const char* out = std::getenv("LABELMESH_BENCH_OUT")) {
        const std::string stem = phantom_stem(out, shape, grid);
        (void)surface::write_surface(made->marching_cubes, stem + "-mc.stl",
                                     surface::SurfaceFormat::kStl);
        (void)surface::write_surface(made->slicer, stem + "-slicer.stl",
                                     surface::SurfaceFormat::kStl);
        (void)surface::write_surface(made->ours, stem + "-ours.stl", surface::SurfaceFormat::kStl);
        (void)volume::write_label_volume(made->volume, stem + ".nii.gz");
      }
      const auto e_mc = testing::shape_error(made->marching_cubes, shape);
      const auto e_slicer = testing::shape_error(made->slicer, shape);
      const auto e_ours = testing::shape_error(made->ours, shape);
      std::printf("%-10s %-18s | %8.3f / %8.1f   | %8.3f / %8.1f   | %8.3f / %8.1f   | %.2f %s\n",
                  shape.name.c_str(), grid.name, e_mc.rms_mm, e_mc.normal_p95_deg, e_slicer.rms_mm,
                  e_slicer.normal_p95_deg, e_ours.rms_mm, e_ours.normal_p95_deg,
                  e_ours.rms_mm / smallest, made->method.c_str());
    }
  }
  return failures;
}

// The phantoms on the axis-aligned grids with the slices shifted by 0, 1/4,
// 1/2 and 3/4 of a slice: where a shape ends between slice centres decides
// how much of it the voxels show, so each method's error is averaged over
// where the slices fall, each figure's worst shift printed beside.
int bench_alignments() {
  const std::vector<Grid> grids{
      {"3 mm", {3, 3, 3}, 0}, {"1x1x3 mm", {1, 1, 3}, 0}, {"0.6x0.6x4 mm", {0.6, 0.6, 4}, 0}};
  const std::vector<AnalyticShape> shapes = phantom_shapes();
  constexpr int kShifts = 4;
  // LABELMESH_BENCH_SHIFTS=1 prints each shift's row too.
  const bool print_shifts = std::getenv("LABELMESH_BENCH_SHIFTS") != nullptr;
  std::printf("mean over %d shifts of the slices (each figure's worst shift)\n", kShifts);
  std::printf("%-10s %-13s | %-26s | %-26s | %-26s\n", "shape", "grid", "MC rms mm / p95 deg",
              "Slicer-like", "ours");
  int failures = 0;
  for (const auto& grid : grids) {
    for (const auto& shape : shapes) {
      struct Sum {
        double rms = 0, p95 = 0, worst_rms = 0, worst_p95 = 0;
        void add(const testing::ShapeError& e) {
          rms += e.rms_mm / kShifts;
          p95 += e.normal_p95_deg / kShifts;
          worst_rms = std::max(worst_rms, e.rms_mm);
          worst_p95 = std::max(worst_p95, e.normal_p95_deg);
        }
      } mc, slicer, ours;
      bool made_all = true;
      for (int shift = 0; shift < kShifts; ++shift) {
        Grid shifted = grid;
        shifted.shift_slices = double(shift) / kShifts;
        const auto made = phantom_surfaces(shape, shifted);
        if (!made) {
          made_all = false;
          break;
        }
        const auto slicer_error = testing::shape_error(made->slicer, shape);
        const auto our_error = testing::shape_error(made->ours, shape);
        mc.add(testing::shape_error(made->marching_cubes, shape));
        slicer.add(slicer_error);
        ours.add(our_error);
        if (print_shifts)
          std::printf("  %-10s %-13s %.2f slice up: Slicer-like %.3f / %.1f, ours %.3f / %.1f\n",
                      shape.name.c_str(), grid.name, shifted.shift_slices, slicer_error.rms_mm,
                      slicer_error.normal_p95_deg, our_error.rms_mm, our_error.normal_p95_deg);
      }
      if (!made_all) {
        ++failures;
        continue;
      }
      std::printf("%-10s %-13s", shape.name.c_str(), grid.name);
      for (const Sum* s : {&mc, &slicer, &ours})
        std::printf(" | %5.3f (%5.3f) / %4.1f (%4.1f)", s->rms, s->worst_rms, s->p95, s->worst_p95);
      std::printf("\n");
    }
  }
  return failures;
}

// The axis-aligned share of each surface beside the true shape's (the true
// normals at our triangles' centres): what a perfect surface would score.
int bench_shares() {
  const std::vector<Grid> grids{{"3 mm", {3, 3, 3}, 0},
                                {"0.98x0.98x2 mm", {0.976562, 0.976562, 2}, 0},
                                {"1x1x3 mm", {1, 1, 3}, 0},
                                {"0.6x0.6x4 mm", {0.6, 0.6, 4}, 0},
                                {"1x1x3 mm oblique", {1, 1, 3}, 25}};
  const std::vector<AnalyticShape> shapes{testing::sphere_shape(25),
                                          testing::ellipsoid_shape(32, 22, 15),
                                          testing::torus_shape(25, 9), testing::column_shape(20)};
  std::printf("%-10s %-18s | axis-aligned %%: true  MC  Slicer-like  ours (method)\n", "shape",
              "grid");
  int failures = 0;
  for (const auto& grid : grids) {
    for (const auto& shape : shapes) {
      const auto made = phantom_surfaces(shape, grid);
      if (!made) {
        ++failures;
        continue;
      }
      const auto& g = made->volume.geometry;
      if (const char* out = std::getenv("LABELMESH_BENCH_OUT"))
        (void)volume::write_label_volume(made->volume, phantom_stem(out, shape, grid) + ".nii.gz");
      std::printf("%-10s %-18s | %5.1f %5.1f %5.1f %5.1f (%s)\n", shape.name.c_str(), grid.name,
                  100 * surface::axis_aligned_share(made->ours, g, shape.normal),
                  100 * surface::axis_aligned_share(made->marching_cubes, g),
                  100 * surface::axis_aligned_share(made->slicer, g),
                  100 * surface::axis_aligned_share(made->ours, g), made->method.c_str());
    }
  }
  return failures;
}

// Points whose triangles' angles miss a full turn by more than this, or pass
// it, count as sharp: the spikes and pinches a render shows (an octahedron's
// corners miss it by 2.09).
constexpr double kSharpDeficitRad = 2.0;

struct VolumeFigures {
  std::vector<double> ours_share, slicer_share, mc_share;  // labels >= 1000 voxels
  // The Slicer-like surfaces against the voxels, per label.
  std::vector<double> slicer_misclassified, slicer_hausdorff, slicer_volume;
  // Where the labels were meshed on their drawn grid: each judged on the other grid.
  std::vector<double> ours_file_misclassified, slicer_drawn_misclassified, slicer_drawn_volume;
  int slicer_drawn_within = 0;
  int labels = 0, ours_within = 0, slicer_within = 0, ours_within_slicer_plus5 = 0;
  double ours_min_angle = 180;
  int ours_poisson = 0;
  // Nodes over all labels, ours and Marching Cubes', and the labels whose
  // surface has more than Marching Cubes' plus two per component.
  uint64_t ours_nodes = 0, mc_nodes = 0;
  int labels_above_mc_nodes = 0;
  // Points sharper than kSharpDeficitRad (sharp_points.h), over all labels.
  testing::SharpPoints ours_sharp, slicer_sharp;
  // Our caps' rims on the volume's edge (rim_turns.h), over all labels.
  testing::RimTurns ours_rims;
  // Triangles, and those with an angle below 30 degrees, over all labels.
  uint64_t ours_triangles = 0, ours_below_30 = 0, slicer_triangles = 0, slicer_below_30 = 0;
  uint64_t mc_triangles = 0, mc_below_30 = 0;
};

// Our surfaces without the guard's checks: the file read, the shared net
// built and smoothed as the pipeline does by default, and every label cut
// out of it, on two threads as the pipeline's are.
// On the grid the labels were drawn on, as the pipeline's (a volume
// resampled from a coarser grid is taken back to it); where the pipeline
// then cuts thick slices thinner, this leaves that step out.
void our_surfaces_alone(const std::string& path) {
  auto read = read_volume(path);
  if (!read) return;
  const auto& labels = read->labels;
  if (const auto grid = volume::find_drawn_grid(read->volume); grid.resampled()) {
    auto drawn = volume::resample_to_drawn_grid(read->volume, grid);
    if (!drawn.ok()) return;
    read->volume = std::move(*drawn);
  }
  conforming::InterfaceFigures figures;
  const auto net = conforming::label_interfaces(read->volume, labels,
                                                net_interface_params(our_params().net), figures);
  // Each thread takes the next label in turn, as the pipeline's do.
  std::atomic<size_t> next{0};
  const auto cut = [&] {
    for (size_t i = next++; i < labels.size(); i = next++)
      (void)conforming::net_label_surface(net, labels[i], read->volume.geometry);
  };
  side_by_side(cut, cut);
}

// Nodes of one label's surface more than 0.1 of the smallest spacing inside
// another label's, ours (shared interfaces) against the Slicer-like surfaces
// (each label smoothed on its own).
void print_overlap(const MeshResult& result, const std::vector<int32_t>& labels,
                   const std::vector<surface::LabelSurface>& slicer,
                   const volume::LabelVolume& volume) {
  std::vector<const surface::TriangleMesh*> ours_meshes, slicer_meshes;
  std::vector<int32_t> meshed;
  for (size_t i = 0; i < labels.size() && i < slicer.size(); ++i) {
    for (const auto& s : result.surfaces) {
      if (labels[i] == 0 || s.label != labels[i] || !s.is_output || s.mesh.triangles.empty())
        continue;
      ours_meshes.push_back(&s.mesh);
      slicer_meshes.push_back(&slicer[i].mesh);
      meshed.push_back(labels[i]);
    }
  }
  const auto& spacing = volume.geometry.spacing;
  const double depth = 0.1 * *std::min_element(spacing.begin(), spacing.end());
  const auto ours_overlap = testing::nodes_inside_others(ours_meshes, meshed, volume, depth);
  const auto slicer_overlap = testing::nodes_inside_others(slicer_meshes, meshed, volume, depth);
  std::printf(
      "  nodes more than %.2f mm inside another label's surface: ours %zu of %zu (%zu labels), "
      "Slicer-like %zu of %zu (%.1f %%, %zu labels)\n",
      depth, ours_overlap.inside, ours_overlap.nodes, ours_overlap.labels_entering,
      slicer_overlap.inside, slicer_overlap.nodes,
      100.0 * double(slicer_overlap.inside) / double(std::max<size_t>(1, slicer_overlap.nodes)),
      slicer_overlap.labels_entering);
}

int bench_volume(const std::string& path, int rounds) {
  std::printf("\n%s\n", path.c_str());
  // Time: both pipelines from the file to every label's surface, and our
  // surfaces without the checks, alternating.
  std::vector<double> ours_s, alone_s, slicer_s;
  absl::StatusOr<MeshResult> result;
  std::vector<surface::LabelSurface> slicer;
  for (int r = 0; r < rounds; ++r) {
    ours_s.push_back(seconds_of([&] { result = run_pipeline(path, our_params(), RunContext{}); }));
    alone_s.push_back(seconds_of([&] { our_surfaces_alone(path); }));
    slicer_s.push_back(seconds_of([&] {
      const auto read = read_volume(path);
      if (read)
        slicer = testing::slicer_like_surfaces(read->volume, read->statistics, read->labels);
    }));
  }
  if (!result.ok()) {
    std::printf("  ours failed: %s\n", std::string(result.status().message()).c_str());
    return 1;
  }
  std::vector<double> ratios, alone_ratios;
  for (int r = 0; r < rounds; ++r) {
    ratios.push_back(ours_s[r] / slicer_s[r]);
    alone_ratios.push_back(alone_s[r] / slicer_s[r]);
  }
  std::printf(
      "  seconds, median of %d alternating: ours %.2f, Slicer-like %.2f, ratio %.2f "
      "(pairs %.2f-%.2f)\n",
      rounds, median(ours_s), median(slicer_s), median(ratios),
      *std::min_element(ratios.begin(), ratios.end()),
      *std::max_element(ratios.begin(), ratios.end()));
  std::printf("  our surfaces without the checks: %.2f s, ratio %.2f (pairs %.2f-%.2f)\n",
              median(alone_s), median(alone_ratios),
              *std::min_element(alone_ratios.begin(), alone_ratios.end()),
              *std::max_element(alone_ratios.begin(), alone_ratios.end()));
  // Where our last run's time went; stages of labels meshed side by side
  // add up, so they sum to more than the run's wall time.
  std::printf("  our last run's stages, seconds summed over labels:");
  for (const auto& stage : result->stages)
    std::printf(" %s %.2f", stage.name.c_str(), stage.seconds);
  std::printf("\n");

  // The Slicer-like surfaces measured as ours are, against the voxels.
  const auto read = read_volume(path);
  if (!read) return 1;
  const auto& volume = read->volume;
  const auto& statistics = read->statistics;
  const auto& labels = read->labels;
  conforming::InterfaceParams flat;
  flat.smoothing_rounds = 0;
  flat.subdivide_thick_quads = false;
  conforming::InterfaceFigures figures;
  const auto staircase = conforming::label_interfaces(volume, labels, flat, figures);
  // Where the pipeline meshed on the grid the labels were drawn on.
  std::optional<volume::LabelVolume> drawn;
  volume::VolumeStatistics drawn_statistics;
  std::optional<conforming::InterfaceSurface> drawn_staircase;
  if (result->input.file_geometry) {
    auto taken = volume::resample_to_drawn_grid(volume, volume::find_drawn_grid(volume));
    if (taken.ok()) {
      drawn = std::move(*taken);
      drawn_statistics = volume::compute_label_statistics(*drawn);
      drawn_staircase = conforming::label_interfaces(*drawn, labels, flat, figures);
    }
  }
  VolumeFigures f;
  for (size_t i = 0; i < labels.size() && i < slicer.size(); ++i) {
    const auto* label = statistics.find(labels[i]);
    const SurfaceResult* ours = nullptr;
    const SurfaceResult* mc = nullptr;
    for (const auto& s : result->surfaces) {
      if (s.label != labels[i]) continue;
      if (s.is_output) ours = &s;
      if (s.stage == "marching_cubes") mc = &s;
    }
    if (ours == nullptr || !ours->fidelity) continue;
    ++f.labels;
    const auto& chosen = ours->fidelity->attempts[ours->fidelity->delivered];
    if (chosen.within_tolerance) ++f.ours_within;
    if (!chosen.within_tolerance && chosen.voxels &&
        std::getenv("LABELMESH_BENCH_LABELS") != nullptr)
      std::printf(
          "    label %d (%zu voxels) outside: %s, volume %+.1f %%, misclassified %.2f %%, "
          "farthest %.2f, Hausdorff %.2f voxels\n",
          labels[i], size_t(label->voxels), ours->stage.c_str(), 100 * chosen.voxels->volume_change,
          100 * chosen.voxels->misclassified_fraction(),
          chosen.voxels->farthest_misclassified_voxels, chosen.voxels->hausdorff_voxels);
    if (!chosen.within_tolerance && std::getenv("LABELMESH_BENCH_ATTEMPTS") != nullptr)
      for (const auto& a : ours->fidelity->attempts)
        std::printf(
            "      attempt: error '%s', misclassified %.2f %%, farthest %.2f, volume %+.2f %%\n",
            a.error.c_str(), a.voxels ? 100 * a.voxels->misclassified_fraction() : -1.0,
            a.voxels ? a.voxels->farthest_misclassified_voxels : -1.0,
            a.voxels ? 100 * a.voxels->volume_change : -1.0);
    if (ours->stage.rfind("poisson", 0) == 0) ++f.ours_poisson;
    f.ours_min_angle = std::min(f.ours_min_angle, ours->statistics.min_angle_deg);
    f.ours_triangles += ours->statistics.triangles;
    f.ours_below_30 += ours->statistics.triangles_below_30_deg;
    const auto slicer_statistics = surface::compute_surface_statistics(slicer[i].mesh);
    f.slicer_triangles += slicer_statistics.triangles;
    f.slicer_below_30 += slicer_statistics.triangles_below_30_deg;
    if (mc != nullptr) {
      f.mc_triangles += mc->statistics.triangles;
      f.mc_below_30 += mc->statistics.triangles_below_30_deg;
      f.ours_nodes += ours->statistics.nodes;
      f.mc_nodes += mc->statistics.nodes;
      if (ours->statistics.nodes > mc->statistics.nodes + 2 * mc->statistics.components)
        ++f.labels_above_mc_nodes;
    }
    const auto add_sharp = [](const surface::TriangleMesh& mesh, testing::SharpPoints& sum) {
      const testing::SharpPoints counted = testing::sharp_points(mesh, kSharpDeficitRad);
      sum.points += counted.points;
      sum.sharp += counted.sharp;
    };
    add_sharp(ours->mesh, f.ours_sharp);
    add_sharp(slicer[i].mesh, f.slicer_sharp);
    testing::add_rim_turns(ours->mesh, drawn ? drawn->geometry : volume.geometry, f.ours_rims);
    if (const char* out = std::getenv("LABELMESH_BENCH_OUT")) {
      const std::string stem = std::string(out) + "/label" + std::to_string(labels[i]);
      (void)surface::write_surface(slicer[i].mesh, stem + "-slicer.stl",
                                   surface::SurfaceFormat::kStl);
      (void)surface::write_surface(ours->mesh, stem + "-ours.stl", surface::SurfaceFormat::kStl);
    }
    auto slicer_voxels = surface::measure_voxel_fidelity(slicer[i].mesh, volume, *label, {});
    if (!slicer_voxels.ok()) continue;
    const auto cut = conforming::net_label_surface(staircase, labels[i], volume.geometry);
    slicer_voxels->hausdorff_voxels = surface::sampled_hausdorff_voxels(
        slicer[i].mesh, cut.staircase, volume.geometry, RunContext{});
    f.slicer_misclassified.push_back(100 * slicer_voxels->misclassified_fraction());
    f.slicer_hausdorff.push_back(slicer_voxels->hausdorff_voxels);
    f.slicer_volume.push_back(100 * std::abs(slicer_voxels->volume_change));
    SurfaceAttempt attempt;
    attempt.voxels = *slicer_voxels;
    if (is_within(attempt, ours->fidelity->tolerance)) ++f.slicer_within;
    if (drawn) {
      // Each surface judged on the other grid too.
      const auto* drawn_label = drawn_statistics.find(labels[i]);
      auto ours_on_file = surface::measure_voxel_fidelity(ours->mesh, volume, *label, {});
      auto slicer_on_drawn =
          drawn_label ? surface::measure_voxel_fidelity(slicer[i].mesh, *drawn, *drawn_label, {})
                      : absl::StatusOr<surface::VoxelFidelity>(absl::NotFoundError("label"));
      if (ours_on_file.ok())
        f.ours_file_misclassified.push_back(100 * ours_on_file->misclassified_fraction());
      if (slicer_on_drawn.ok()) {
        f.slicer_drawn_misclassified.push_back(100 * slicer_on_drawn->misclassified_fraction());
        f.slicer_drawn_volume.push_back(100 * std::abs(slicer_on_drawn->volume_change));
        const auto drawn_cut =
            conforming::net_label_surface(*drawn_staircase, labels[i], drawn->geometry);
        slicer_on_drawn->hausdorff_voxels = surface::sampled_hausdorff_voxels(
            slicer[i].mesh, drawn_cut.staircase, drawn->geometry, RunContext{});
        SurfaceAttempt on_drawn;
        on_drawn.voxels = *slicer_on_drawn;
        if (is_within(on_drawn, ours->fidelity->tolerance)) ++f.slicer_drawn_within;
      }
    }
    if (label->voxels < 1000) continue;
    const double our_share = ours->axis_aligned_share.value_or(1);
    f.ours_share.push_back(our_share);
    f.slicer_share.push_back(slicer_voxels->axis_aligned_share);
    if (mc && mc->axis_aligned_share) f.mc_share.push_back(*mc->axis_aligned_share);
    if (our_share <= slicer_voxels->axis_aligned_share + 0.05) ++f.ours_within_slicer_plus5;
    // LABELMESH_BENCH_LABELS=1 prints each label's shares.
    if (std::getenv("LABELMESH_BENCH_LABELS") != nullptr)
      std::printf(
          "    label %d (%zu voxels): share MC %.1f %%, Slicer-like %.1f %%, ours %.1f %%; "
          "misclassified Slicer-like %.1f %%, ours %.2f %% (%s)\n",
          labels[i], size_t(label->voxels),
          mc && mc->axis_aligned_share ? 100 * *mc->axis_aligned_share : -1.0,
          100 * slicer_voxels->axis_aligned_share, 100 * our_share,
          100 * slicer_voxels->misclassified_fraction(),
          chosen.voxels ? 100 * chosen.voxels->misclassified_fraction() : -1.0,
          ours->stage.c_str());
  }
  std::printf(
      "  labels %d: within the voxel tolerance ours %d, Slicer-like %d; ours by Poisson %d; "
      "ours min angle %.1f deg\n",
      f.labels, f.ours_within, f.slicer_within, f.ours_poisson, f.ours_min_angle);
  std::printf(
      "  nodes over all labels: ours %llu, Marching Cubes %llu (ratio %.2f); labels above "
      "Marching Cubes' count plus two per component: %d\n",
      static_cast<unsigned long long>(f.ours_nodes), static_cast<unsigned long long>(f.mc_nodes),
      double(f.ours_nodes) / double(std::max<uint64_t>(1, f.mc_nodes)), f.labels_above_mc_nodes);
  std::printf(
      "  sharp points (angles around them more than %.0f rad short of a turn or over it): "
      "ours %zu of %zu (%.2f %%), Slicer-like %zu of %zu (%.2f %%)\n",
      kSharpDeficitRad, f.ours_sharp.sharp, f.ours_sharp.points,
      100.0 * double(f.ours_sharp.sharp) / double(std::max<size_t>(1, f.ours_sharp.points)),
      f.slicer_sharp.sharp, f.slicer_sharp.points,
      100.0 * double(f.slicer_sharp.sharp) / double(std::max<size_t>(1, f.slicer_sharp.points)));
  if (f.ours_rims.points > 0)
    std::printf(
        "  rims of caps on the volume's edge: %zu points, turning %.1f deg on average, more than "
        "30 deg at %.1f %%\n",
        f.ours_rims.points, f.ours_rims.sum_deg / double(f.ours_rims.points),
        100.0 * double(f.ours_rims.over_30_deg) / double(f.ours_rims.points));
  const auto per_million = [](uint64_t part, uint64_t whole) {
    return 1e6 * double(part) / double(std::max<uint64_t>(1, whole));
  };
  std::printf(
      "  triangles with an angle below 30 deg: ours %llu of %llu (%.0f per million), "
      "Slicer-like %llu of %llu (%.0f per million), Marching Cubes %llu of %llu (%.0f per "
      "million)\n",
      static_cast<unsigned long long>(f.ours_below_30),
      static_cast<unsigned long long>(f.ours_triangles),
      per_million(f.ours_below_30, f.ours_triangles),
      static_cast<unsigned long long>(f.slicer_below_30),
      static_cast<unsigned long long>(f.slicer_triangles),
      per_million(f.slicer_below_30, f.slicer_triangles),
      static_cast<unsigned long long>(f.mc_below_30),
      static_cast<unsigned long long>(f.mc_triangles), per_million(f.mc_below_30, f.mc_triangles));
  std::printf(
      "  Slicer-like against the voxels, median over labels: misclassified %.2f %% of boundary "
      "voxels, Hausdorff %.2f voxels, |volume change| %.2f %%\n",
      median(f.slicer_misclassified), median(f.slicer_hausdorff), median(f.slicer_volume));
  std::printf(
      "  axis-aligned share, median over %zu labels >= 1000 voxels: MC %.1f %%, "
      "Slicer-like %.1f %%, ours %.1f %%; ours within Slicer-like + 5 points: %d\n",
      f.ours_share.size(), 100 * median(f.mc_share), 100 * median(f.slicer_share),
      100 * median(f.ours_share), f.ours_within_slicer_plus5);
  // LABELMESH_BENCH_OVERLAP=1: how far the labels' surfaces enter each
  // other (minutes on the brain and the frog).
  if (std::getenv("LABELMESH_BENCH_OVERLAP") != nullptr)
    print_overlap(*result, labels, slicer, volume);
  if (drawn) {
    const auto& g = drawn->geometry;
    std::printf(
        "  meshed on the drawn grid %.3f x %.3f x %.3f mm; median misclassified boundary "
        "voxels: ours on the file's grid %.2f %%, Slicer-like on the drawn grid %.2f %% "
        "(|volume change| %.2f %%; within the tolerance there: %d)\n",
        g.spacing[0], g.spacing[1], g.spacing[2], median(f.ours_file_misclassified),
        median(f.slicer_drawn_misclassified), median(f.slicer_drawn_volume), f.slicer_drawn_within);
  }
  return 0;
}

int bench_three_slices(int rounds) {
  // LABELMESH_BENCH_OUT=DIR keeps the volume there, to mesh again.
  const char* out = std::getenv("LABELMESH_BENCH_OUT");
  const auto path =
      (out != nullptr ? std::filesystem::path(out) : std::filesystem::temp_directory_path()) /
      "labelmesh-five-labels-three-slices.nii.gz";
  if (const auto written =
          volume::write_label_volume(testing::five_organs_on_three_slices(), path.string());
      !written.ok()) {
    std::printf("could not write %s: %s\n", path.c_str(), std::string(written.message()).c_str());
    return 1;
  }
  const int failures = bench_volume(path.string(), rounds);
  if (out == nullptr) std::filesystem::remove(path);
  return failures;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "all";
  const int rounds = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  std::vector<std::string> files;
  for (int i = 3; i < argc; ++i) files.push_back(argv[i]);
  if (files.empty()) {
    const std::string data = LABELMESH_SHARED_DATA;
    for (const char* name :
         {"totalseg_example_seg_dicom.nii.gz", "totalseg_example_seg_fast_force_split.nii.gz",
          "totalseg_example_seg_mr.nii.gz", "MRIcrop-seg_converted.nii.gz",
          "msd_prostate_mask_00.nii", "iso2mesh_brain_seg_converted.nii.gz", "frogtissue.mhd"})
      files.push_back(data + "/" + name);
  }
  int failures = 0;
  if (what == "phantoms" || what == "all") failures += bench_phantoms();
  if (what == "alignments" || what == "all") failures += bench_alignments();
  if (what == "shares" || what == "all") failures += bench_shares();
  if (what == "volumes" || what == "all")
    for (const auto& f : files) failures += bench_volume(f, rounds);
  if (what == "slices" || what == "all") failures += bench_three_slices(rounds);
  if (what == "blurs")
    for (const auto& f : files) failures += bench_blurs(f);
  return failures == 0 ? 0 : 1;
}
