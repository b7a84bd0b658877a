// SPDX-License-Identifier: AGPL-3.0-or-later
// Our own bounded walk over the header of a DICOM Part-10 Segmentation file,
// written from the standard (PS3.10 section 7 for the file layout, PS3.5
// sections 7.1-7.5 for data elements, sequences and items). It runs on
// untrusted uploads before any library reader sees the file, so every length
// is checked against the file size and a header budget before it is used,
// and nothing is allocated from a length the file declares.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace labelmesh::volume::internal {

// The fields of a Segmentation header we mesh from, as stored: no semantic
// checks (is it a SEG, is the geometry 3-D) are made here.
struct DicomSegHeader {
  std::string sop_class_uid;                // (0008,0016), trailing NUL/space stripped
  std::string transfer_syntax_uid;          // (0002,0010)
  uint16_t rows = 0, columns = 0;           // (0028,0010), (0028,0011); 0 when absent
  uint32_t frames = 1;                      // (0028,0008) NumberOfFrames, default 1
  uint16_t bits_allocated = 0;              // (0028,0100); 0 when absent
  std::string segmentation_type;            // (0062,0001) "BINARY" / "FRACTIONAL" (stripped)
  uint32_t maximum_fractional_value = 0;    // (0062,000E), 0 if absent
  uint32_t segments = 0;                    // items in SegmentSequence (0062,0002)
  std::vector<uint16_t> segment_numbers;    // (0062,0004) of each item, in order; 0 if missing
  uint64_t pixel_data_offset = 0;           // file offset of the (7FE0,0010) value, bytes
  uint64_t pixel_data_bytes = 0;            // its declared (defined) length, bytes
  std::string dimension_organization_type;  // (0020,9311) if present, e.g. "TILED_FULL"
  // From the Shared (5200,9229) and Per-frame (5200,9230) Functional Groups;
  // each single value is the shared one, else the first frame's.
  std::optional<std::array<double, 6>> orientation;    // ImageOrientationPatient (0020,0037)
  std::optional<std::array<double, 2>> pixel_spacing;  // (0028,0030): row, column spacing, mm
  std::optional<double> slice_thickness;               // (0018,0050), mm
  std::optional<double> spacing_between_slices;        // (0018,0088), mm
  // ImagePositionPatient (0020,0032) of each frame, mm; a shared one applies
  // to every frame. Size == frames when per-frame groups or a shared position
  // are present, else empty.
  std::vector<std::optional<std::array<double, 3>>> frame_positions;
  // ReferencedSegmentNumber (0062,000B) of each frame, 0 where none is given;
  // sized like frame_positions (per-frame groups or a shared number).
  std::vector<uint16_t> frame_segments;
  bool has_plane_position_slide = false;  // (0048,021A) seen anywhere (slide microscopy)
};

// Walks the header of the DICOM Part-10 file at `path` up to its top-level
// Pixel Data (7FE0,0010). Transfer syntaxes: implicit VR little endian,
// explicit VR little and big endian; any other is refused.
// Limits: the header before Pixel Data at most `max_header_bytes` bytes,
// sequences nested at most 8 deep, at most 1,000,000 frames and 65,535
// segments.
// Errors: NOT_FOUND when the file does not exist; INVALID_ARGUMENT
// "<path>: <(gggg,eeee) Name>: <problem>" for anything malformed, truncated or
// over a limit. Free-text values are never echoed; a transfer syntax UID only
// when it is a plain UID.
absl::StatusOr<DicomSegHeader> parse_dicom_seg_header(const std::string& path,
                                                      uint64_t max_header_bytes = uint64_t{64}
                                                                                  << 20);

// True when `uid` is 1 to 64 digits and dots, so it may be shown in messages.
bool is_plain_uid(std::string_view uid);

}  // namespace labelmesh::volume::internal
