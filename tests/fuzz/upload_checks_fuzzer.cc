// SPDX-License-Identifier: AGPL-3.0-or-later
// Fuzzes check_uploaded_volume, what labelmeshd runs on an upload before it
// becomes a job, with a bounded voxel limit and worker memory. The first
// byte picks the upload's extension (as upload_extension would store it),
// the other bytes are the upload. An accepted upload must keep the header
// contract and fit the worker; a refusal must name the file "upload", never
// the spool path.
#include <cstdint>
#include <iterator>
#include <string>

#include "core/header/volume_header.h"
#include "fuzz/fuzz_support.h"
#include "server/upload_checks.h"

namespace {

using labelmesh::fuzzing::contract_broken;

constexpr const char* kExtensions[] = {".nii", ".nii.gz", ".mha", ".nrrd",
                                       ".inr", ".inr.gz", ".vti"};
constexpr uint64_t kMaxVoxels = uint64_t{1} << 24;
constexpr uint64_t kWorkerMemoryBytes = uint64_t{256} << 20;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > labelmesh::fuzzing::kMaxInputBytes) return 0;
  const std::string extension = kExtensions[data[0] % std::size(kExtensions)];
  auto stored_as = labelmesh::server::upload_extension("scan" + extension);
  if (!stored_as.ok() || *stored_as != extension)
    contract_broken("upload_extension does not keep an upload extension");
  const labelmesh::fuzzing::ScratchFile file(extension, data + 1, size - 1);

  auto geometry =
      labelmesh::server::check_uploaded_volume(file.path(), kMaxVoxels, kWorkerMemoryBytes);
  if (!geometry.ok()) {
    const std::string directory = labelmesh::fuzzing::ScratchDirectory::get().string();
    if (geometry.status().message().find(directory) != std::string::npos)
      contract_broken("a refusal names the spool path");
    return 0;
  }
  labelmesh::fuzzing::check_geometry_contract(*geometry, kMaxVoxels);
  // One byte per voxel for a label's mask, beside the voxels themselves.
  if (2 * static_cast<uint64_t>(geometry->voxel_count()) > kWorkerMemoryBytes)
    contract_broken("more voxels than a worker holds");
  return 0;
}
