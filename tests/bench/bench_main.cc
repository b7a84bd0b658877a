// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmesh_bench [FILE... | --cancellation | --volumes]: per-stage seconds, voxels per second and
// peak RSS for reading and Marching Cubes, beside the baselines they are held to: a plain
// decompress + scan of the voxels, and VTK's discrete flying edges run directly on the whole
// volume. Then the quality-surface pipeline (MC, repair, smoothing, Poisson solve and meshing,
// checks) on the liver's label 255 and a 256^3 sphere, stage by stage; then TetGen and the
// improvement pass on the liver with Q histograms before and after, the mixed and hexahedral meshes
// beside TetGen's, and how fast a stop request ends a run of the liver. Prints figures; never fails
// on time.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iterator>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkNew.h>
#include <vtkPolyData.h>

#include "bench/mesh3_baseline.h"
#include "core/conforming/conforming_mesher.h"
#include "core/header/payload_stream.h"
#include "core/pipeline/label_mixed_meshes.h"
#include "core/pipeline/label_tet_meshes.h"
#include "core/pipeline/pipeline.h"
#include "core/surface/extract_surfaces.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/label_statistics.h"
#include "core/volume/phantom.h"
#include "core/volume/read_label_volume.h"
#include "core/volume/write_label_volume.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

// Best of `runs` timings, so one slow run on a busy machine does not decide.
template <typename F>
double best_of(int runs, F&& f) {
  double best = 1e30;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    f();
    best = std::min(best, seconds_since(start));
  }
  return best;
}

int bench_file(const std::string& path) {
  using namespace labelmesh;
  auto header = volume::check_volume_header(path);
  if (!header.ok()) {
    std::fprintf(stderr, "%s\n", std::string(header.status().message()).c_str());
    return 1;
  }
  const double voxels = double(header->geometry.voxel_count());
  constexpr int kRuns = 3;

  // Baseline: decode the voxel bytes and touch each once.
  uint64_t checksum = 0;
  const double baseline = best_of(kRuns, [&] {
    auto stream = volume::internal::PayloadStream::open(header->data_path, header->file_offset,
                                                        header->encoding, header->compressed_bytes);
    (void)(*stream)->skip(header->decoded_offset);
    std::vector<char> bytes(header->data_bytes());
    (void)(*stream)->read(bytes.data(), bytes.size());
    for (char c : bytes) checksum += static_cast<unsigned char>(c);
  });

  absl::StatusOr<volume::LabelVolume> read;
  const double read_seconds =
      best_of(kRuns, [&] { read = volume::read_label_volume(path, {}, {}); });
  if (!read.ok()) return 1;
  volume::VolumeStatistics stats;
  const double stats_seconds =
      best_of(kRuns, [&] { stats = volume::compute_label_statistics(*read); });
  std::vector<int32_t> labels;
  for (const auto& l : stats.labels) labels.push_back(l.label);

  size_t our_triangles = 0;
  const double mc_seconds = best_of(kRuns, [&] {
    auto surfaces = surface::extract_surfaces(*read, stats, labels, RunContext{});
    our_triangles = 0;
    for (const auto& s : *surfaces) our_triangles += s.mesh.triangles.size();
  });
  int64_t vtk_triangles = 0;
  const double vtk_seconds = best_of(kRuns, [&] {
    vtkNew<vtkDiscreteFlyingEdges3D> contour;
    contour->SetInputData(read->voxels);
    for (size_t i = 0; i < labels.size(); ++i) contour->SetValue(int(i), labels[i]);
    contour->ComputeNormalsOff();
    contour->ComputeGradientsOff();
    contour->ComputeScalarsOff();
    contour->Update();
    vtk_triangles = contour->GetOutput()->GetNumberOfPolys();
  });

  std::printf("%s\n", path.c_str());
  std::printf("  voxels                      %.0f (%zu labels), checksum %llu\n", voxels,
              labels.size(), static_cast<unsigned long long>(checksum));
  std::printf("  decompress + scan baseline  %8.3f s\n", baseline);
  std::printf(
      "  read + validate             %8.3f s  %7.1f Mvoxel/s  ratio to baseline %.2f (target <= "
      "2)\n",
      read_seconds, voxels / read_seconds / 1e6, read_seconds / baseline);
  std::printf("  label statistics            %8.3f s  %7.1f Mvoxel/s\n", stats_seconds,
              voxels / stats_seconds / 1e6);
  std::printf("  marching cubes (labelmesh)  %8.3f s  %7.1f Mvoxel/s  %zu triangles\n", mc_seconds,
              voxels / mc_seconds / 1e6, our_triangles);
  std::printf("  VTK flying edges, direct    %8.3f s  %7.1f Mvoxel/s  %lld triangles\n",
              vtk_seconds, voxels / vtk_seconds / 1e6, static_cast<long long>(vtk_triangles));
  std::printf("  MC ratio to VTK direct      %8.2f (target <= 1.2)\n", mc_seconds / vtk_seconds);
  std::printf("  peak RSS                    %8.1f MiB (target < 1024 on the liver)\n",
              peak_rss_mib());
  return 0;
}

// The default Poisson pipeline on `labels` of `path`, stage by stage.
int bench_quality_surface(const std::string& path, const std::vector<int32_t>& labels) {
  labelmesh::MeshParams params;
  params.labels = labels;
  const auto start = Clock::now();
  auto result = labelmesh::run_pipeline(path, params, labelmesh::RunContext{});
  const double total = seconds_since(start);
  if (!result.ok()) {
    std::fprintf(stderr, "%s\n", std::string(result.status().message()).c_str());
    return 1;
  }
  std::printf("%s, labels", path.c_str());
  for (int32_t label : labels) std::printf(" %d", label);
  std::printf(": poisson pipeline %.2f s (target <= 10 s on the liver)\n", total);
  for (const auto& stage : result->stages)
    std::printf("  %-27s %8.3f s\n", stage.name.c_str(), stage.seconds);
  for (const auto& surface : result->surfaces) {
    if (!surface.is_output) continue;
    const auto& st = surface.statistics;
    std::printf("  label %d: %u nodes, %u triangles, angles %.2f-%.2f deg", surface.label, st.nodes,
                st.triangles, st.min_angle_deg, st.max_angle_deg);
    if (surface.poisson) {
      std::printf(", %zu of %zu points, %d CG iterations", surface.poisson->used_points,
                  surface.poisson->input_points, surface.poisson->solver_iterations);
    }
    if (surface.distance_to_marching_cubes) {
      std::printf(", Hausdorff %.3f mm, mean %.3f mm",
                  surface.distance_to_marching_cubes->hausdorff_mm,
                  surface.distance_to_marching_cubes->mean_mm);
    }
    std::printf("\n");
  }
  std::printf("  peak RSS                    %8.1f MiB (target <= 1024 on the liver)\n",
              peak_rss_mib());
  return 0;
}

// Counts of `quality` in the Table 1 bins, with the good ones split further.
// Prints `title`, then how many of `values` fall in each bin (lower, upper];
// the last bound reaches just past 1 so that 1 counts.
void print_histogram(const std::string& title, const std::vector<double>& values,
                     std::span<const double> upper) {
  std::vector<size_t> counts(upper.size(), 0);
  for (double value : values) {
    size_t bin = 0;
    while (bin + 1 < upper.size() && value > upper[bin]) ++bin;
    ++counts[bin];
  }
  std::printf("%s", title.c_str());
  double lower = -1;
  for (size_t bin = 0; bin < upper.size(); ++bin) {
    std::printf(" (%.3g,%.3g] %zu", lower, std::min(upper[bin], 1.0), counts[bin]);
    lower = upper[bin];
  }
  std::printf("\n");
}

void print_quality_histogram(const char* name, const std::vector<double>& quality) {
  static constexpr double kUpper[] = {0.001, 1.0 / 30, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0 + 1e-12};
  char title[64];
  std::snprintf(title, sizeof title, "  %-10s Q histogram:", name);
  print_histogram(title, quality, kUpper);
}

// TetGen on the liver's Poisson surface, then the improvement pass: time,
// peak RSS and the quality histogram before and after.
int bench_tetrahedra(const std::string& path, const std::vector<int32_t>& labels) {
  labelmesh::MeshParams params;
  params.labels = labels;
  params.volume = labelmesh::VolumeMethod::kTetgen;
  params.improve.target_quality = 0;  // run below, timed on its own
  const auto pipeline_start = Clock::now();
  auto result = labelmesh::run_pipeline(path, params, labelmesh::RunContext{});
  if (!result.ok() || !result->volume) {
    std::fprintf(stderr, "%s\n", std::string(result.status().message()).c_str());
    return 1;
  }
  labelmesh::VolumeResult& volume = *result->volume;
  const std::vector<double> before = volume.quality;
  const auto tetgen_summary = volume.summary;
  const auto start = Clock::now();
  labelmesh::MeshParams defaults;
  defaults.labels = labels;
  const auto improve = labelmesh::improve_params_for(defaults, result->input.geometry);
  if (!labelmesh::improve_volume(volume, improve, labelmesh::RunContext{}).ok()) return 1;
  const double improve_seconds = seconds_since(start);
  const double ours = seconds_since(pipeline_start);
  const auto& s = volume.summary;
  const auto& f = volume.improvement->figures;
  std::printf("%s: tetrahedra\n", path.c_str());
  std::printf(
      "  tetgen                      %8.3f s  %zu tetrahedra, Q min %.3f, dihedral %.1f-%.1f\n",
      volume.seconds, before.size(), tetgen_summary.min, tetgen_summary.min_dihedral_deg,
      tetgen_summary.max_dihedral_deg);
  std::printf(
      "  improvement pass            %8.3f s  %zu tetrahedra, Q min %.3f, dihedral %.1f-%.1f "
      "(target Q >= 0.2, dihedral >= 10)\n",
      improve_seconds, volume.mesh.tetrahedra.size(), s.min, s.min_dihedral_deg,
      s.max_dihedral_deg);
  std::printf(
      "  flips 3-2 %zu, 2-3 %zu; points moved %zu, inserted %zu; slivers peeled %zu (%.2f mm3, "
      "%.2f mm deep)\n",
      f.flips_3_2, f.flips_2_3, f.vertices_moved, f.vertices_inserted, f.slivers_peeled,
      f.peeled_volume_mm3, f.peel_depth_mm);
  print_quality_histogram("tetgen", before);
  print_quality_histogram("improved", volume.quality);
  std::printf("  file to improved tetrahedra %8.3f s, peak RSS %.1f MiB\n", ours, peak_rss_mib());

  // The baseline: CGAL Mesh_3 on the same label of the same image.
  auto volume_in = labelmesh::volume::read_label_volume(path, {}, {});
  if (!volume_in.ok()) return 1;
  auto mesh3 = labelmesh::bench::mesh_label_with_mesh3(*volume_in, labels.front());
  if (!mesh3.ok()) {
    std::fprintf(stderr, "%s\n", std::string(mesh3.status().message()).c_str());
    return 1;
  }
  const auto& m = mesh3->quality;
  std::printf(
      "  CGAL Mesh_3 (1 thread)      %8.3f s  %zu tetrahedra, %zu nodes, Q min %.3f mean %.3f, "
      "dihedral %.1f-%.1f, questionable %lld\n",
      mesh3->seconds, mesh3->tetrahedra, mesh3->nodes, m.min, m.mean, m.min_dihedral_deg,
      m.max_dihedral_deg, static_cast<long long>(m.invalid + m.very_bad + m.questionable));
  std::printf("  ours / Mesh_3 time          %8.2f (target < 1)\n", ours / mesh3->seconds);

  // Each once more, in turn: on this shared machine a slow spell can take
  // 15 % off one side of a single pair of runs.
  labelmesh::MeshParams whole;
  whole.labels = labels;
  whole.volume = labelmesh::VolumeMethod::kTetgen;
  const auto again_start = Clock::now();
  if (!labelmesh::run_pipeline(path, whole, labelmesh::RunContext{}).ok()) return 1;
  const double ours_again = seconds_since(again_start);
  auto mesh3_again = labelmesh::bench::mesh_label_with_mesh3(*volume_in, labels.front());
  if (!mesh3_again.ok()) return 1;
  const double ours_best = std::min(ours, ours_again);
  const double mesh3_best = std::min(mesh3->seconds, mesh3_again->seconds);
  std::printf("  second runs                 ours %.3f s, Mesh_3 %.3f s\n", ours_again,
              mesh3_again->seconds);
  std::printf("  best of two, ours / Mesh_3  %8.2f (%.3f s / %.3f s; target < 1)\n",
              ours_best / mesh3_best, ours_best, mesh3_best);
  return 0;
}

// Seconds of the named stages of a run.
double stage_seconds(const labelmesh::MeshResult& result,
                     std::initializer_list<const char*> names) {
  double seconds = 0;
  for (const auto& stage : result.stages)
    for (const char* name : names)
      if (stage.name == name) seconds += stage.seconds;
  return seconds;
}

// One volume mesh of the liver's label 255, in this (child) process: the
// volume stage's seconds, element counts, Jacobian ratio histogram and the
// process's peak RSS, which the surface stages set before it.
int bench_one_volume(const std::string& path, labelmesh::VolumeMethod method, double hex_mm,
                     double interior_mm) {
  labelmesh::MeshParams params;
  params.labels = {255};
  params.volume = method;
  params.hex_size_mm = hex_mm;
  params.hex_interior_size_mm = interior_mm;
  auto result = labelmesh::run_pipeline(path, params, labelmesh::RunContext{});
  if (!result.ok()) {
    std::fprintf(stderr, "%s\n", std::string(result.status().message()).c_str());
    return 1;
  }
  if (result->volume) {
    const auto& v = *result->volume;
    std::printf(
        "  tet                %7.2f s  %zu tetrahedra, %zu nodes, Q min %.3f, good %lld, "
        "peak RSS %.0f MiB\n",
        stage_seconds(*result, {"tetgen", "tet_improve"}), v.mesh.tetrahedra.size(),
        v.mesh.points.size(), v.summary.min, static_cast<long long>(v.summary.good),
        peak_rss_mib());
    return 0;
  }
  if (!result->mixed) return 1;
  const auto& m = *result->mixed;
  const auto& q = m.quality;
  std::printf(
      "  %s %.0f mm%s%-6s %7.2f s  %zu hexahedra (%.1f %%), %zu pyramids, %zu tetrahedra, %zu "
      "nodes; JR min %.3f mean %.3f, scaled Jacobian min %.3f, good %lld, inverted %zu, volume "
      "%+.3f %%, tetrahedral layer on %zu label(s), peak RSS %.0f MiB\n",
      method == labelmesh::VolumeMethod::kHex ? "hex  " : "mixed", hex_mm,
      interior_mm > 0 ? "/" : "", interior_mm > 0 ? std::to_string(int(interior_mm)).c_str() : "",
      stage_seconds(*result, {"mixed_mesh"}), q.hexahedra,
      100.0 * double(q.hexahedra) / double(std::max<size_t>(1, m.mesh.size())), q.pyramids,
      q.tetrahedra, m.mesh.points.size(), q.jacobian_ratio_min, q.jacobian_ratio_mean,
      q.scaled_jacobian_min.value_or(0), static_cast<long long>(q.cell_summary.good), q.invalid,
      100 * (q.volume_mm3 / m.surface_volume_mm3 - 1), m.tetrahedral_layer_labels.size(),
      peak_rss_mib());
  static constexpr double kUpper[] = {0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0 + 1e-12};
  std::vector<double> ratios;
  for (size_t c = 0; c < m.mesh.size(); ++c)
    if (m.mesh.types[c] != labelmesh::mixed_mesh::CellType::kTetra)
      ratios.push_back(q.jacobian_ratio[c]);
  print_histogram("    JR histogram (hexahedra, pyramids):", ratios, kUpper);
  return 0;
}

// Stops a run of the liver's label 255 (through TetGen) at one time after
// another and prints how long each stop took to return, and in which stage
// it came (each should take under 1 s).
int bench_cancellation(const std::string& path, const std::vector<int32_t>& labels) {
  labelmesh::MeshParams params;
  params.labels = labels;
  params.volume = labelmesh::VolumeMethod::kTetgen;
  std::printf("%s: cancellation (stop requested at t, returned after)\n", path.c_str());
  double worst = 0;
  for (double delay = 0.4; delay < 12; delay += 1.0) {
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::string stage = "read";
    labelmesh::RunContext context;
    context.stop = &stop;
    // Stages on two threads report at once.
    context.progress = [&](const labelmesh::ProgressUpdate& update) {
      std::lock_guard<std::mutex> lock(mutex);
      stage = std::string(update.stage);
    };
    absl::StatusCode code = absl::StatusCode::kOk;
    std::thread run([&] { code = labelmesh::run_pipeline(path, params, context).status().code(); });
    std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    std::string stopped_in;
    {
      std::lock_guard<std::mutex> lock(mutex);
      stopped_in = stage;
    }
    const auto stopped_at = Clock::now();
    stop.store(true);
    run.join();
    const double latency = seconds_since(stopped_at);
    if (code != absl::StatusCode::kCancelled) {
      std::printf("  t = %4.1f s  finished before the stop\n", delay);
      break;
    }
    worst = std::max(worst, latency);
    std::printf("  t = %4.1f s  in %-20s returned after %6.3f s\n", delay, stopped_in.c_str(),
                latency);
  }
  std::printf("  slowest return               %6.3f s (target < 1)\n", worst);
  return 0;
}

// A sphere phantom filling a 256^3 grid (radius 125 voxels), written to /tmp.
std::string write_large_sphere() {
  const auto phantom =
      labelmesh::volume::make_phantom(labelmesh::volume::PhantomShape::kSphere, 6.25);
  const std::string path = "/tmp/labelmesh-bench-sphere256.nii.gz";
  if (!labelmesh::volume::write_label_volume(phantom.volume, path).ok()) return "";
  return path;
}

// Runs `job` in a child process, so that its peak RSS is its own.
template <typename F>
bool in_child(F&& job) {
  const pid_t child = fork();
  if (child == 0) {
    const int code = job();
    std::fflush(stdout);
    _exit(code);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// The liver's volume meshes, each in its own process (its own peak RSS),
// TetGen's and ours in turn, twice over, then the finer and hexahedral ones.
int bench_volumes(const std::string& liver) {
  using labelmesh::VolumeMethod;
  std::printf("%s: volume meshes of label 255 (volume stage seconds)\n", liver.c_str());
  std::fflush(stdout);
  bool ok = true;
  for (int round = 0; round < 2; ++round) {
    ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kTetgen, 0, 0); });
    ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kMixed, 2, 0); });
    ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kTetgen, 0, 0); });
    ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kMixed, 2, 8); });
  }
  ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kHex, 2, 0); });
  ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kMixed, 1, 0); });
  ok &= in_child([&] { return bench_one_volume(liver, VolumeMethod::kMixed, 1, 8); });
  return ok ? 0 : 1;
}

// The shared multi-label volumes.
std::vector<std::string> conforming_examples() {
  const std::string data = LABELMESH_SHARED_DATA;
  return {data + "/totalseg_example_seg_fast_force_split.nii.gz",
          data + "/iso2mesh_brain_seg_converted.nii.gz", data + "/MRIcrop-seg_converted.nii.gz",
          data + "/msd_prostate_mask_00.nii", data + "/liver.inr.gz"};
}

// One conforming mesh of every label of `path`, in this (child) process: its
// figures, then CGAL Mesh_3 on the same labels, run in turn `pairs` times.
int bench_conforming_file(const std::string& path, int pairs) {
  using namespace labelmesh;
  auto volume = volume::read_label_volume(path, {}, {});
  if (!volume.ok()) {
    std::fprintf(stderr, "%s\n", std::string(volume.status().message()).c_str());
    return 1;
  }
  const auto& spacing = volume->geometry.spacing;
  std::vector<double> ours_seconds, mesh3_seconds;
  for (int pair = 0; pair < pairs; ++pair) {
    conforming::ConformingFigures figures;
    volume_mesh::ImproveFigures improve;
    const auto start = Clock::now();
    auto mesh = conforming::mesh_conforming(*volume, {}, {}, RunContext{}, figures, improve);
    ours_seconds.push_back(seconds_since(start));
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), std::string(mesh.status().message()).c_str());
      return 1;
    }
    // Ours runs first, so the peak so far is ours (with the volume read).
    if (pair == 0) std::printf("  ours peak RSS %.1f MiB\n", peak_rss_mib());
    // Mesh_3 sized by the voxels ours meshed: the input's, or the coarser
    // blocks when the interfaces were too large.
    const auto& f = figures.coarsening.factors;
    const double voxel = std::cbrt(spacing[0] * f[0] * spacing[1] * f[1] * spacing[2] * f[2]);
    const bench::Mesh3Sizing sizing{voxel, 0.5 * voxel, voxel};
    auto mesh3 = bench::mesh_labels_with_mesh3(*volume, sizing);
    if (!mesh3.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), std::string(mesh3.status().message()).c_str());
      return 1;
    }
    mesh3_seconds.push_back(mesh3->seconds);
    if (pair > 0) continue;

    const auto summary = volume_mesh::summarise_quality(*mesh);
    size_t below = 0;
    for (size_t t = 0; t < mesh->tetrahedra.size(); ++t) {
      const auto& v = mesh->tetrahedra[t];
      const quality::Tet tet{mesh->points[v[0]], mesh->points[v[1]], mesh->points[v[2]],
                             mesh->points[v[3]]};
      below +=
          quality::tetra_quality(tet) < 0.2 || quality::tetra_dihedral_range_deg(tet).first < 10;
    }
    const auto ours_spread = conforming::volume_change_spread(figures.labels, 1000);
    const auto& i = figures.interfaces;
    const auto& c = figures.conformity;
    std::printf("%s: conforming mesh of %zu labels\n", path.c_str(), figures.labels.size());
    std::printf(
        "  interfaces   %8.3f s  %zu points (%zu on junctions, %zu held to curves, %zu fixed), "
        "%zu triangles, within %.2f mm of the voxel boundary\n",
        i.seconds, i.points, i.junction_points, i.curve_points, i.fixed_points, i.triangles,
        i.max_offset_mm);
    std::printf("  grid         %8.3f s  %llu voxel faces between labels; spacing x %.2f %.2f %.2f",
                figures.grid_seconds, (unsigned long long)figures.coarsening.interface_faces, f[0],
                f[1], f[2]);
    if (figures.thick_slices.axis >= 0) {
      std::printf("; thick axis %d cut into %d (shape-based interpolation)",
                  figures.thick_slices.axis, figures.thick_slices.parts);
    }
    std::printf("\n");
    std::printf("  crossings    repairs %d, points restored %zu, staircase only %d\n",
                figures.crossing_repairs, figures.restored_points, int(figures.staircase_only));
    std::printf("  tetgen       %8.3f s  %zu tetrahedra, %zu regions (%zu outside)\n",
                figures.tetgen.seconds, figures.tetgen.tetrahedra, figures.regions.regions,
                figures.regions.outside_regions);
    std::printf("  slides       %8.3f s  %zu points moved; below Q 0.3 or 15 deg %zu -> %zu\n",
                figures.slide.seconds, figures.slide.points_moved,
                figures.slide.tetrahedra_below_before, figures.slide.tetrahedra_below_after);
    std::printf("  improvement  %8.3f s  Q min %.3f -> %.3f\n", improve.seconds,
                improve.quality_min_before, improve.quality_min_after);
    std::printf(
        "  ours         %zu tetrahedra, %zu nodes, Q min %.3f mean %.3f, dihedral "
        "%.1f-%.1f, below Q 0.2 or 10 deg %zu\n",
        mesh->tetrahedra.size(), mesh->points.size(), summary.min, summary.mean,
        summary.min_dihedral_deg, summary.max_dihedral_deg, below);
    std::printf(
        "  conformity   %s; %zu interfaces, %zu shared faces, %zu outer faces, volume "
        "gap %.1e\n",
        c.ok() ? "ok" : c.failures().c_str(), c.interfaces, c.interface_faces, c.outer_faces,
        c.volume_gap_fraction());
    std::printf(
        "  ours volume error, %zu labels >= 1000 voxels: median %.2f %%, p90 %.2f %%, "
        "max %.2f %%\n",
        ours_spread.labels, 100 * ours_spread.median, 100 * ours_spread.p90, 100 * ours_spread.max);
    std::vector<conforming::LabelVolumeFigures> theirs;
    for (const auto& figure : figures.labels) {
      auto copy = figure;
      copy.mesh_volume_mm3 = 0;
      copy.tetrahedra = 0;
      for (const auto& label : mesh3->labels) {
        if (label.label == figure.label) {
          copy.mesh_volume_mm3 = label.volume_mm3;
          copy.tetrahedra = label.tetrahedra;
        }
      }
      theirs.push_back(copy);
    }
    const auto mesh3_spread = conforming::volume_change_spread(theirs, 1000);
    size_t mesh3_missing = 0;
    for (const auto& label : theirs) mesh3_missing += label.tetrahedra == 0;
    const auto& m = mesh3->quality;
    std::printf(
        "  Mesh_3       %zu tetrahedra, %zu nodes, Q min %.3f mean %.3f, dihedral "
        "%.1f-%.1f; labels without cells %zu (facet size %.2f, distance %.2f, cell "
        "size %.2f mm)\n",
        mesh3->tetrahedra, mesh3->nodes, m.min, m.mean, m.min_dihedral_deg, m.max_dihedral_deg,
        mesh3_missing, sizing.facet_size_mm, sizing.facet_distance_mm, sizing.cell_size_mm);
    std::printf("  Mesh_3 volume error: median %.2f %%, p90 %.2f %%, max %.2f %%\n",
                100 * mesh3_spread.median, 100 * mesh3_spread.p90, 100 * mesh3_spread.max);
  }
  for (int pair = 0; pair < pairs; ++pair) {
    std::printf("  run %d        ours %.3f s, Mesh_3 %.3f s, ratio %.2f\n", pair + 1,
                ours_seconds[pair], mesh3_seconds[pair], ours_seconds[pair] / mesh3_seconds[pair]);
  }
  std::printf("  peak RSS     %.1f MiB (both)\n", peak_rss_mib());
  return 0;
}

int bench_conforming(const std::vector<std::string>& files) {
  int failures = 0;
  for (const auto& file : files) {
    // The first volume (the 61 labels) in turn twice, the others once.
    const int pairs = &file == &files.front() ? 2 : 1;
    if (!in_child([&] { return bench_conforming_file(file, pairs); })) ++failures;
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Line by line, so a run stopped by a time limit keeps what it printed.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const std::string liver_path = std::string(LABELMESH_SHARED_DATA) + "/liver.inr.gz";
  // The cancellation figures alone: labelmesh_bench --cancellation.
  if (argc == 2 && std::string(argv[1]) == "--cancellation")
    return in_child([&] { return bench_cancellation(liver_path, {255}); }) ? 0 : 1;
  // The volume meshes alone: labelmesh_bench --volumes.
  if (argc == 2 && std::string(argv[1]) == "--volumes") return bench_volumes(liver_path);
  std::vector<std::string> files;
  const bool conforming = argc > 1 && std::string(argv[1]) == "--conforming";
  for (int i = conforming ? 2 : 1; i < argc; ++i) files.emplace_back(argv[i]);
  // Conforming meshes of every label, ours beside Mesh_3: labelmesh_bench --conforming [FILE...].
  if (conforming) {
    if (files.empty()) files = conforming_examples();
    return bench_conforming(files);
  }
  if (files.empty()) {
    files = {liver_path, std::string(LABELMESH_SHARED_DATA) + "/vb-seg.mha"};
  }
  int failures = 0;
  for (const auto& file : files) {
    if (!in_child([&] { return bench_file(file); })) ++failures;
  }
  if (argc == 1) {
    const std::string liver = files[0];
    if (bench_volumes(liver) != 0) ++failures;
    if (!in_child([&] { return bench_quality_surface(liver, {255}); })) ++failures;
    if (!in_child([&] { return bench_tetrahedra(liver, {255}); })) ++failures;
    if (!in_child([&] { return bench_cancellation(liver, {255}); })) ++failures;
    const std::string sphere = write_large_sphere();
    if (sphere.empty() || !in_child([&] { return bench_quality_surface(sphere, {1}); })) ++failures;
  }
  return failures == 0 ? 0 : 1;
}
