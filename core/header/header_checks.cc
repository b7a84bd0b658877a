// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/header_checks.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "core/header/payload_stream.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {}  // namespace

absl::Status field_error(std::string_view path, std::string_view field, std::string_view problem) {
  return absl::InvalidArgumentError(cat(path, ": ", field, ": ", problem));
}

std::string show(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.9g", value);
  return buffer;
}

absl::Status check_dims(std::string_view path, std::string_view field,
                        const std::array<int64_t, 3>& dims, const ReadLimits& limits) {
  uint64_t product = 1;
  for (int axis = 0; axis < 3; ++axis) {
    if (dims[axis] < 1) {
      return field_error(
          path, field,
          cat("size ", dims[axis], " along axis ", axis, "; every size must be at least 1"));
    }
    const auto size = static_cast<uint64_t>(dims[axis]);
    if (dims[axis] > std::numeric_limits<int32_t>::max()) {
      return field_error(path, field,
                         cat("size ", dims[axis], " along axis ", axis,
                             " exceeds the 2^31 - 1 voxels one axis can hold"));
    }
    if (size > limits.max_voxels || product > limits.max_voxels / size) {
      return field_error(path, field,
                         cat(dims[0], " x ", dims[1], " x ", dims[2],
                             " voxels exceeds the limit of ", limits.max_voxels));
    }
    product *= size;
  }
  return absl::OkStatus();
}

absl::Status check_spacing(std::string_view path, std::string_view field,
                           const std::array<double, 3>& spacing) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(spacing[axis]) || spacing[axis] <= 0) {
      return field_error(path, field,
                         cat("spacing ", show(spacing[axis]), " along axis ", axis,
                             " must be finite and positive"));
    }
  }
  return absl::OkStatus();
}

absl::Status check_finite(std::string_view path, std::string_view field, const double* values,
                          int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      return field_error(path, field, cat("value ", i, " is not a finite number"));
    }
  }
  return absl::OkStatus();
}

absl::Status normalise_direction(std::string_view path, std::string_view field,
                                 std::array<double, 9>& d) {
  LABELMESH_RETURN_IF_ERROR(check_finite(path, field, d.data(), 9));
  for (int c = 0; c < 3; ++c) {
    const double norm = std::sqrt(d[c] * d[c] + d[3 + c] * d[3 + c] + d[6 + c] * d[6 + c]);
    if (!(norm > 1e-12)) {
      return field_error(path, field, cat("axis ", c, " has a zero direction"));
    }
    for (int r = 0; r < 3; ++r) d[3 * r + c] /= norm;
  }
  const double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                     d[2] * (d[3] * d[7] - d[4] * d[6]);
  if (std::abs(det) < 1e-6) {
    return field_error(path, field, "the voxel axes are coplanar (singular direction matrix)");
  }
  return absl::OkStatus();
}

absl::StatusOr<uint64_t> file_size(std::string_view path) {
  std::error_code error;
  const std::filesystem::path p(path);
  if (!std::filesystem::is_regular_file(p, error)) {
    return absl::NotFoundError(cat(path, ": no such file"));
  }
  const auto size = std::filesystem::file_size(p, error);
  if (error) return absl::NotFoundError(cat(path, ": cannot read the file size"));
  return static_cast<uint64_t>(size);
}

absl::StatusOr<std::string> read_prefix(std::string_view path, uint64_t max_bytes, bool gzip) {
  auto stream =
      PayloadStream::open(std::string(path), 0, gzip ? DataEncoding::kGzip : DataEncoding::kRaw);
  if (!stream.ok()) return stream.status();
  std::string bytes(max_bytes, '\0');
  LABELMESH_ASSIGN_OR_RETURN(auto got, (*stream)->read(bytes.data(), max_bytes));
  bytes.resize(got);
  return bytes;
}

absl::Status check_raw_payload(std::string_view path, uint64_t offset, uint64_t needed) {
  LABELMESH_ASSIGN_OR_RETURN(auto size, file_size(path));
  if (size < offset || size - offset < needed) {
    return field_error(path, "voxel data",
                       cat("is truncated: the header needs ", needed, " bytes at offset ", offset,
                           ", the file has ", size, " bytes"));
  }
  return absl::OkStatus();
}

absl::Status check_encoded_payload(std::string_view path, uint64_t file_offset,
                                   DataEncoding encoding, uint64_t compressed_bytes,
                                   uint64_t needed) {
  LABELMESH_ASSIGN_OR_RETURN(auto size, file_size(path));
  if (encoding == DataEncoding::kGzip && compressed_bytes == 0 && needed < (uint64_t{1} << 32) &&
      size >= file_offset + 18) {
    // ISIZE, the last four bytes of a gzip member, is its decoded size modulo
    // 2^32: a free check for the common single-member file.
    std::ifstream in(std::string(path), std::ios::binary);
    in.seekg(static_cast<std::streamoff>(size - 4));
    unsigned char tail[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(tail), 4);
    const uint32_t isize = uint32_t{tail[0]} | uint32_t{tail[1]} << 8 | uint32_t{tail[2]} << 16 |
                           uint32_t{tail[3]} << 24;
    if (in && isize >= needed) return absl::OkStatus();
  }
  auto stream = PayloadStream::open(std::string(path), file_offset, encoding, compressed_bytes);
  if (!stream.ok()) return stream.status();
  LABELMESH_ASSIGN_OR_RETURN(auto got, (*stream)->skip(needed));
  if (got < needed) {
    return field_error(path, "voxel data",
                       cat("is truncated: the header needs ", needed,
                           " decoded bytes, the compressed stream holds ", got));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<double>> parse_numbers(std::string_view path, std::string_view field,
                                                  std::string_view text, size_t count) {
  std::vector<double> values;
  for (std::string_view token : split_any(text, " \t\r,()")) {
    double value = 0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) {
      return field_error(path, field, cat("value ", values.size(), " is not a number"));
    }
    values.push_back(value);
    if (values.size() > count) break;
  }
  if (values.size() != count) {
    return field_error(path, field,
                       cat("needs ", count, " numbers, found ",
                           values.size() > count ? "more" : std::to_string(values.size())));
  }
  if (auto status = check_finite(path, field, values.data(), static_cast<int>(count));
      !status.ok()) {
    return status;
  }
  return values;
}

absl::StatusOr<std::array<int64_t, 3>> whole_sizes(std::string_view path, std::string_view field,
                                                   const std::vector<double>& values) {
  std::array<int64_t, 3> dims{};
  for (int axis = 0; axis < 3; ++axis) {
    const double d = values[axis];
    if (d != std::floor(d) || d < 1 || d > 1e12) {
      return field_error(
          path, field, cat("size ", show(d), " along axis ", axis, " must be a whole number >= 1"));
    }
    dims[axis] = static_cast<int64_t>(d);
  }
  return dims;
}

std::string sibling_path(std::string_view path, std::string_view name) {
  return (std::filesystem::path(path).parent_path() / std::filesystem::path(name)).string();
}

bool is_plain_file_name(std::string_view name) {
  return !name.empty() && name.front() != '.' && name.find('/') == std::string_view::npos &&
         name.find('\\') == std::string_view::npos && name.find('\0') == std::string_view::npos;
}

}  // namespace labelmesh::volume::internal
