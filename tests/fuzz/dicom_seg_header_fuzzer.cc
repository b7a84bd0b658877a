// SPDX-License-Identifier: AGPL-3.0-or-later
// Fuzzes the DICOM SEG header walk and the grid its frames are placed on,
// through check_volume_header on a .dcm file. An accepted header must keep
// its contract: a grid within the voxel limit and pixel data inside the file.
#include <cstdint>
#include <filesystem>

#include "core/header/dicom_seg_header.h"
#include "core/header/volume_header.h"
#include "fuzz/fuzz_support.h"

namespace {

using labelmesh::fuzzing::contract_broken;

constexpr uint64_t kMaxVoxels = uint64_t{1} << 24;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace volume = labelmesh::volume;
  if (size > labelmesh::fuzzing::kMaxInputBytes) return 0;
  const labelmesh::fuzzing::ScratchFile file(".dcm", data, size);
  // The walk alone, on everything, then the whole header check.
  auto walked = volume::internal::parse_dicom_seg_header(file.path());
  if (walked.ok()) {
    if (walked->pixel_data_offset + walked->pixel_data_bytes > size)
      contract_broken("pixel data past the end of the file");
    if (walked->frame_segments.size() != 0 && walked->frame_segments.size() != walked->frames)
      contract_broken("a segment number for some frames only");
  }
  volume::ReadLimits limits;
  limits.max_voxels = kMaxVoxels;
  auto header = volume::check_volume_header(file.path(), limits);
  if (!header.ok()) return 0;
  if (!walked.ok()) contract_broken("the header passed, its walk did not");
  labelmesh::fuzzing::check_geometry_contract(header->geometry, kMaxVoxels);
  if (header->format != volume::ImageFormat::kDicomSeg) contract_broken("not read as DICOM SEG");
  return 0;
}
