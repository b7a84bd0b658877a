// labelmesh_bench [FILE...]: per-stage seconds, voxels per second and peak
// RSS for reading and Marching Cubes, beside the baselines they are held to:
// a plain decompress + scan of the voxels, and VTK's discrete flying edges
// run directly on the whole volume. Prints figures; never fails on time.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkNew.h>
#include <vtkPolyData.h>

#include "core/surface/extract_surfaces.h"
#include "core/surface/surface_statistics.h"
#include "core/volume/label_statistics.h"
#include "core/volume/payload_stream.h"
#include "core/volume/read_label_volume.h"

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

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) files.emplace_back(argv[i]);
  if (files.empty()) {
    files = {std::string(LABELMESH_SHARED_DATA) + "/liver.inr.gz",
             std::string(LABELMESH_SHARED_DATA) + "/vb-seg.mha"};
  }
  int failures = 0;
  for (const auto& file : files) {
    // One child per file, so each peak RSS is that file's own.
    const pid_t child = fork();
    if (child == 0) {
      const int code = bench_file(file);
      std::fflush(stdout);
      _exit(code);
    }
    int status = 0;
    waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) ++failures;
  }
  return failures == 0 ? 0 : 1;
}
