// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks shared by the per-format header parsers: field errors that name the
// file, overflow-safe dimension products, and bounded looks at payloads.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/header/volume_header.h"

namespace labelmesh::volume::internal {

// The problem named when ReadLimits::allow_data_file is false.
inline constexpr std::string_view kNoDataFileHere =
    "a separate data file is not accepted here; send a file that holds its voxels "
    "(.nii, .mha, .nrrd with attached data)";

// INVALID_ARGUMENT "<file>: <field>: <problem>".
absl::Status field_error(std::string_view path, std::string_view field, std::string_view problem);

// Each dimension >= 1 and the product within limits.max_voxels.
absl::Status check_dims(std::string_view path, std::string_view field,
                        const std::array<int64_t, 3>& dims, const ReadLimits& limits);

// Each spacing finite and > 0.
absl::Status check_spacing(std::string_view path, std::string_view field,
                           const std::array<double, 3>& spacing);

// Every value finite.
absl::Status check_finite(std::string_view path, std::string_view field, const double* values,
                          int count);

// Direction columns normalised in place; errors when a column is zero or the
// axes are (nearly) coplanar.
absl::Status normalise_direction(std::string_view path, std::string_view field,
                                 std::array<double, 9>& direction);

absl::StatusOr<uint64_t> file_size(std::string_view path);

// Up to `max_bytes` from the start of the file, gunzipped when `gzip`.
absl::StatusOr<std::string> read_prefix(std::string_view path, uint64_t max_bytes, bool gzip);

// The file holds at least offset + needed bytes.
absl::Status check_raw_payload(std::string_view path, uint64_t offset, uint64_t needed);
// The gzip or zlib stream that starts at `file_offset` (bounded by
// `compressed_bytes`, 0 = to the end) decodes to at least `needed` bytes.
// Inflates no more than that, whatever the stream holds.
absl::Status check_encoded_payload(std::string_view path, uint64_t file_offset,
                                   DataEncoding encoding, uint64_t compressed_bytes,
                                   uint64_t needed);

// Whitespace-separated numbers; errors name the field when a value is not a
// number or the count differs.
absl::StatusOr<std::vector<double>> parse_numbers(std::string_view path, std::string_view field,
                                                  std::string_view text, size_t count);

// Three sizes that must be whole numbers >= 1 (DimSize, sizes, ...).
absl::StatusOr<std::array<int64_t, 3>> whole_sizes(std::string_view path, std::string_view field,
                                                   const std::vector<double>& values);

// The directory part of `path` joined with `name` (for detached data files).
std::string sibling_path(std::string_view path, std::string_view name);

// True when `name` is a plain file name: no directory part, not hidden.
bool is_plain_file_name(std::string_view name);

// Formatting helper for values in messages.
std::string show(double value);

}  // namespace labelmesh::volume::internal
