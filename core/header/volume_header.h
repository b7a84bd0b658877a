// SPDX-License-Identifier: AGPL-3.0-or-later
// Our own validation of label-volume headers. It runs before any library
// reader sees a file: Debian's VTK 9.1 bundles MetaIO and nifticlib versions
// with published header-overflow bugs, and uploads are untrusted. Every field
// we rely on is checked before anything is allocated from it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/header/image_geometry.h"
#include "core/header/slicer_segments.h"

namespace labelmesh::volume {

enum class ScalarType {
  kInt8,
  kUInt8,
  kInt16,
  kUInt16,
  kInt32,
  kUInt32,
  kInt64,
  kUInt64,
  kFloat32,
  kFloat64
};

std::string_view scalar_type_name(ScalarType type);
int scalar_size(ScalarType type);

// How the voxel bytes are stored in `data_path`.
enum class DataEncoding { kRaw, kGzip, kZlib };

struct ReadLimits {
  // Volumes with more voxels than this are refused before any allocation.
  uint64_t max_voxels = uint64_t{1} << 31;
  // Text headers (MetaImage, NRRD, INR, VTI) longer than this are refused,
  // bytes. A 3D Slicer segmentation writes about 450 bytes per segment.
  uint64_t max_header_bytes = uint64_t{1} << 20;
  // False refuses headers that name a separate data file (MetaImage
  // ElementDataFile, NRRD "data file") before that file is looked for, so an
  // untrusted header cannot probe which paths exist.
  bool allow_data_file = true;
  // DICOM SEG, FRACTIONAL: a pixel is inside its segment when its value over
  // the Maximum Fractional Value is at least this.
  double fractional_threshold = 0.5;
  // DICOM SEG and 3D Slicer segments may overlap. False refuses them, naming
  // the overlapping segments; true keeps each segment whole in the first
  // layer where it overlaps nothing (LabelVolume::more_layers), so each is
  // meshed on its own.
  bool separate_overlapping = false;
};

// Everything the readers need, taken from a header that passed every check.
struct VolumeHeader {
  ImageFormat format = ImageFormat::kNifti;
  ScalarType scalar_type = ScalarType::kUInt8;
  // Placement in LPS, for the voxel order stored in the file.
  ImageGeometry geometry;
  bool big_endian = false;
  // File that holds the voxels: the header file itself unless detached.
  std::string data_path;
  DataEncoding encoding = DataEncoding::kRaw;
  // Where the (raw or encoded) voxel stream starts in data_path.
  uint64_t file_offset = 0;
  // Bytes to skip in the decoded stream before the first voxel: non-zero when
  // the header itself is compressed with the voxels (.nii.gz, .inr.gz).
  uint64_t decoded_offset = 0;
  // Encoded bytes after file_offset that belong to the voxels; 0 = to the end.
  uint64_t compressed_bytes = 0;
  // NIfTI scl_slope/scl_inter; identity elsewhere.
  double rescale_slope = 1.0;
  double rescale_intercept = 0.0;
  // Values stored per voxel, the fastest axis: the layers of a 4-D 3D Slicer
  // segmentation; 1 elsewhere. Counts in data_bytes() and the voxel limit.
  int64_t layers = 1;
  // The segments a 3D Slicer segmentation names (NRRD); empty elsewhere.
  std::vector<SlicerSegment> segments;

  uint64_t data_bytes() const;
};

// The format a path names by its extension, or nullopt.
std::optional<ImageFormat> format_from_path(std::string_view path);

// Whether `path` is a DICOM Part-10 file: "DICM" after its 128-byte
// preamble, whatever its name (dcmqi's label.seg, a PACS file with none).
bool is_dicom_file(const std::string& path);

// The format of `path`: by its extension, else DICOM SEG when its content
// says so, else nullopt.
std::optional<ImageFormat> format_of_file(const std::string& path);

// Parses and checks the header of `path`. Errors are INVALID_ARGUMENT naming
// the file and field ("scan.nii: dim[2]: is 0, ..."), NOT_FOUND for a missing
// file. Never echoes free-text header fields (patient data can hide there).
absl::StatusOr<VolumeHeader> check_volume_header(const std::string& path,
                                                 const ReadLimits& limits = {});

// Decodes every voxel byte of a header that passed check_volume_header, to
// the end of its compressed stream: a stream that is cut short, fails its
// CRC or Adler-32, or has bytes after its end is INVALID_ARGUMENT naming
// the file. The header checks look only as far as the voxels need (or at a
// gzip file's size trailer); this finds the rest before a job is accepted.
// Raw voxels carry no checksum; their length was checked with the header.
absl::Status check_whole_payload(const VolumeHeader& header);

}  // namespace labelmesh::volume
