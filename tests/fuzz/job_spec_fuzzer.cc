// SPDX-License-Identifier: AGPL-3.0-or-later
// Fuzzes what Submit checks of a job spec before any byte is uploaded, as
// meshing_service.cc runs it: check_spec with the default server
// configuration, the options with the job's voxel limit filled in, parsed
// again as the job record stores them (make_options) and as the worker reads
// them back, and the per-label sizing against a few grids. The input is a
// serialized labelmesh.v1.JobSpec.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>

#include "core/header/image_geometry.h"
#include "core/job/job_options.h"
#include "fuzz/fuzz_support.h"
#include "google/protobuf/stubs/logging.h"
#include "labelmesh/v1/service.pb.h"
#include "server/server_config.h"
#include "server/upload_checks.h"

namespace {

using labelmesh::fuzzing::contract_broken;

// Grids a job may meet: isotropic 1 mm, anisotropic 0.7 x 0.7 x 3 mm,
// oblique 0.2 mm, and a coarse 5 mm mirrored one.
labelmesh::volume::ImageGeometry grid(double sx, double sy, double sz,
                                      const std::array<double, 9>& direction) {
  labelmesh::volume::ImageGeometry g;
  g.dims = {64, 64, 32};
  g.spacing = {sx, sy, sz};
  g.direction = direction;
  return g;
}

const labelmesh::volume::ImageGeometry kGrids[] = {
    grid(1, 1, 1, {1, 0, 0, 0, 1, 0, 0, 0, 1}),
    grid(0.7, 0.7, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1}),
    grid(0.2, 0.2, 0.2, {0.8, -0.6, 0, 0.6, 0.8, 0, 0, 0, 1}),
    grid(5, 5, 5, {-1, 0, 0, 0, 1, 0, 0, 0, 1}),
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > labelmesh::fuzzing::kMaxInputBytes) return 0;
  // Parsing logs every string field that is not UTF-8; the harness only
  // needs to know whether parsing failed.
  static const bool quiet = [] {
    google::protobuf::SetLogHandler(nullptr);
    return true;
  }();
  (void)quiet;
  labelmesh::v1::JobSpec spec;
  if (!spec.ParseFromArray(data, static_cast<int>(size))) return 0;
  static const labelmesh::server::ServerConfig config;

  const bool accepted = labelmesh::server::check_spec(spec, config).ok();
  auto params = labelmesh::params_from_options(spec.options());
  if (accepted && !params.ok()) contract_broken("check_spec accepts options that do not parse");
  if (!params.ok()) return 0;

  // Submit: the job's voxel limit is the smaller of the client's and the
  // server's, and the options are stored with every default filled in.
  labelmesh::v1::MeshOptions options = spec.options();
  const uint64_t voxel_limit = options.max_voxels() == 0
                                   ? config.max_voxels
                                   : std::min<uint64_t>(options.max_voxels(), config.max_voxels);
  options.set_max_voxels(voxel_limit);
  auto limited = labelmesh::params_from_options(options);
  if (!limited.ok()) contract_broken("options refused once their voxel limit is set");
  const labelmesh::v1::MeshOptions stored = labelmesh::make_options(*limited);

  // The worker parses the stored options again; they must mean the same job.
  auto in_worker = labelmesh::params_from_options(stored);
  if (!in_worker.ok()) contract_broken("the worker refuses the stored options");
  if (labelmesh::make_options(*in_worker).SerializeAsString() != stored.SerializeAsString())
    contract_broken("the stored options change when the worker reads them");

  for (const auto& geometry : kGrids) {
    const bool fits = labelmesh::check_sizing_for_grid(limited->poisson, geometry).ok();
    if (fits != labelmesh::check_sizing_for_grid(in_worker->poisson, geometry).ok())
      contract_broken("sizing checks differ between the spec and the stored options");
  }
  return 0;
}
