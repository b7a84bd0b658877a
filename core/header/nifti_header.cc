// SPDX-License-Identifier: AGPL-3.0-or-later
// NIfTI-1/2 header checks. Field offsets follow the NIfTI-1 (nifti1.h) and
// NIfTI-2 (nifti2.h) layouts. The affine comes from the sform when
// sform_code > 0, else the qform (quaternion + qfac), else pixdim alone
// ("method 1"). NIfTI is RAS; we convert to LPS by negating x and y.
#include <bit>
#include <cmath>
#include <cstring>

#include "core/header/header_checks.h"
#include "core/header/header_formats.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

constexpr int kNifti1HeaderSize = 348;
constexpr int kNifti2HeaderSize = 540;

// Reads little- or big-endian fields from a header buffer.
class FieldReader {
 public:
  FieldReader(const std::string& bytes, bool swap) : bytes_(bytes), swap_(swap) {}

  template <typename T>
  T get(size_t offset) const {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, bytes_.data() + offset, sizeof(T));
    if (swap_) {
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

 private:
  const std::string& bytes_;
  bool swap_;
};

// The fields we use, widened to one shape for both versions.
struct NiftiFields {
  int version = 1;
  int64_t dim[8] = {};
  int datatype = 0;
  int bitpix = 0;
  double pixdim[8] = {};
  double vox_offset = 0;
  double scl_slope = 0;
  double scl_inter = 0;
  int qform_code = 0;
  int sform_code = 0;
  double quatern[3] = {};
  double qoffset[3] = {};
  double srow[12] = {};
  bool single_file = true;
};

uint32_t byte_swapped(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

NiftiFields read_nifti1(const FieldReader& f) {
  NiftiFields n;
  n.version = 1;
  for (int i = 0; i < 8; ++i) n.dim[i] = f.get<int16_t>(40 + 2 * i);
  n.datatype = f.get<int16_t>(70);
  n.bitpix = f.get<int16_t>(72);
  for (int i = 0; i < 8; ++i) n.pixdim[i] = f.get<float>(76 + 4 * i);
  n.vox_offset = f.get<float>(108);
  n.scl_slope = f.get<float>(112);
  n.scl_inter = f.get<float>(116);
  n.qform_code = f.get<int16_t>(252);
  n.sform_code = f.get<int16_t>(254);
  for (int i = 0; i < 3; ++i) n.quatern[i] = f.get<float>(256 + 4 * i);
  for (int i = 0; i < 3; ++i) n.qoffset[i] = f.get<float>(268 + 4 * i);
  for (int i = 0; i < 12; ++i) n.srow[i] = f.get<float>(280 + 4 * i);
  return n;
}

NiftiFields read_nifti2(const FieldReader& f) {
  NiftiFields n;
  n.version = 2;
  n.datatype = f.get<int16_t>(12);
  n.bitpix = f.get<int16_t>(14);
  for (int i = 0; i < 8; ++i) n.dim[i] = f.get<int64_t>(16 + 8 * i);
  for (int i = 0; i < 8; ++i) n.pixdim[i] = f.get<double>(104 + 8 * i);
  n.vox_offset = static_cast<double>(f.get<int64_t>(168));
  n.scl_slope = f.get<double>(176);
  n.scl_inter = f.get<double>(184);
  n.qform_code = f.get<int32_t>(344);
  n.sform_code = f.get<int32_t>(348);
  for (int i = 0; i < 3; ++i) n.quatern[i] = f.get<double>(352 + 8 * i);
  for (int i = 0; i < 3; ++i) n.qoffset[i] = f.get<double>(376 + 8 * i);
  for (int i = 0; i < 12; ++i) n.srow[i] = f.get<double>(400 + 8 * i);
  return n;
}

absl::StatusOr<ScalarType> nifti_scalar_type(const std::string& path, int datatype, int bitpix) {
  struct Known {
    int code;
    ScalarType type;
  };
  static constexpr Known kKnown[] = {{2, ScalarType::kUInt8},    {4, ScalarType::kInt16},
                                     {8, ScalarType::kInt32},    {16, ScalarType::kFloat32},
                                     {64, ScalarType::kFloat64}, {256, ScalarType::kInt8},
                                     {512, ScalarType::kUInt16}, {768, ScalarType::kUInt32},
                                     {1024, ScalarType::kInt64}, {1280, ScalarType::kUInt64}};
  for (const auto& known : kKnown) {
    if (known.code != datatype) continue;
    if (bitpix != 8 * scalar_size(known.type)) {
      return field_error(
          path, "bitpix",
          cat("is ", bitpix, " but datatype ", datatype, " needs ", 8 * scalar_size(known.type)));
    }
    return known.type;
  }
  return field_error(path, "datatype",
                     cat(datatype,
                         " is not a label type (need an integer or real "
                         "scalar: no complex, RGB or binary voxels)"));
}

// Voxel index -> RAS affine, as a row-major 3x4 matrix.
absl::StatusOr<std::array<double, 12>> nifti_affine(const std::string& path, const NiftiFields& n) {
  std::array<double, 12> a{};
  if (n.sform_code > 0) {
    LABELMESH_RETURN_IF_ERROR(check_finite(path, "srow_x/srow_y/srow_z", n.srow, 12));
    std::copy(n.srow, n.srow + 12, a.begin());
    return a;
  }
  const double qfac = n.pixdim[0] < 0 ? -1.0 : 1.0;
  if (n.qform_code > 0) {
    LABELMESH_RETURN_IF_ERROR(check_finite(path, "quatern_b/c/d", n.quatern, 3));
    LABELMESH_RETURN_IF_ERROR(check_finite(path, "qoffset_x/y/z", n.qoffset, 3));
    const double b = n.quatern[0], c = n.quatern[1], d = n.quatern[2];
    const double sum = b * b + c * c + d * d;
    if (sum > 1.0 + 1e-5) {
      return field_error(path, "quatern_b/c/d", cat("b^2 + c^2 + d^2 = ", show(sum), " exceeds 1"));
    }
    const double q0 = std::sqrt(std::max(0.0, 1.0 - sum));
    const double r[9] = {q0 * q0 + b * b - c * c - d * d,
                         2 * (b * c - q0 * d),
                         2 * (b * d + q0 * c),
                         2 * (b * c + q0 * d),
                         q0 * q0 + c * c - b * b - d * d,
                         2 * (c * d - q0 * b),
                         2 * (b * d - q0 * c),
                         2 * (c * d + q0 * b),
                         q0 * q0 + d * d - c * c - b * b};
    const double scale[3] = {n.pixdim[1], n.pixdim[2], qfac * n.pixdim[3]};
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) a[4 * row + col] = r[3 * row + col] * scale[col];
      a[4 * row + 3] = n.qoffset[row];
    }
    return a;
  }
  a[0] = n.pixdim[1];
  a[5] = n.pixdim[2];
  a[10] = n.pixdim[3];
  return a;
}

}  // namespace

absl::StatusOr<VolumeHeader> check_nifti_header(const std::string& path, bool gzip,
                                                const ReadLimits& limits) {
  auto bytes = read_prefix(path, kNifti2HeaderSize, gzip);
  if (!bytes.ok()) return bytes.status();
  if (bytes->size() < kNifti1HeaderSize) {
    return field_error(
        path, "header",
        cat("is ", bytes->size(), " bytes; a NIfTI header needs ", kNifti1HeaderSize));
  }
  uint32_t sizeof_hdr = 0;
  std::memcpy(&sizeof_hdr, bytes->data(), 4);
  bool swap = false;
  if (sizeof_hdr != kNifti1HeaderSize && sizeof_hdr != kNifti2HeaderSize) {
    sizeof_hdr = byte_swapped(sizeof_hdr);
    swap = true;
  }
  if (sizeof_hdr != kNifti1HeaderSize && sizeof_hdr != kNifti2HeaderSize) {
    return field_error(path, "sizeof_hdr", "is neither 348 (NIfTI-1) nor 540 (NIfTI-2)");
  }
  FieldReader reader(*bytes, swap);
  NiftiFields n;
  if (sizeof_hdr == kNifti1HeaderSize) {
    const std::string_view magic(bytes->data() + 344, 4);
    if (magic == std::string_view("ni1\0", 4)) {
      return field_error(path, "magic", "two-file NIfTI (.hdr/.img) is not supported; use .nii");
    }
    if (magic != std::string_view("n+1\0", 4)) {
      return field_error(path, "magic", "is not \"n+1\" (not a single-file NIfTI-1)");
    }
    n = read_nifti1(reader);
  } else {
    if (bytes->size() < kNifti2HeaderSize) {
      return field_error(path, "header", "is shorter than the 540 bytes of a NIfTI-2 header");
    }
    const std::string_view magic(bytes->data() + 4, 8);
    if (magic.substr(0, 4) == std::string_view("ni2\0", 4)) {
      return field_error(path, "magic", "two-file NIfTI (.hdr/.img) is not supported; use .nii");
    }
    if (magic != std::string_view("n+2\0\r\n\032\n", 8)) {
      return field_error(path, "magic", "is not \"n+2\" (not a single-file NIfTI-2)");
    }
    n = read_nifti2(reader);
  }

  // dim[0] is the rank; a value past 7 is how nifticlib's stack buffer overflows.
  if (n.dim[0] < 1 || n.dim[0] > 7) {
    return field_error(path, "dim[0]", cat("is ", n.dim[0], "; it must be 1 to 7"));
  }
  std::array<int64_t, 3> dims{1, 1, 1};
  for (int axis = 0; axis < 3; ++axis) {
    if (axis < n.dim[0]) dims[axis] = n.dim[axis + 1];
    if (dims[axis] < 1) {
      return field_error(path, cat("dim[", axis + 1, "]"),
                         cat("is ", dims[axis], "; every size must be at least 1"));
    }
  }
  for (int extra = 4; extra <= n.dim[0]; ++extra) {
    if (n.dim[extra] != 1) {
      return field_error(
          path, cat("dim[", extra, "]"),
          cat("is ", n.dim[extra], "; a label volume has one 3-D frame and one component"));
    }
  }
  LABELMESH_RETURN_IF_ERROR(check_dims(path, "dim", dims, limits));
  LABELMESH_ASSIGN_OR_RETURN(auto type, nifti_scalar_type(path, n.datatype, n.bitpix));

  const std::array<double, 3> pixdim{n.pixdim[1], n.pixdim[2], n.pixdim[3]};
  if (n.sform_code <= 0) {
    LABELMESH_RETURN_IF_ERROR(check_spacing(path, "pixdim", pixdim));
  }
  const int minimum_offset = n.version == 1 ? 352 : 544;
  if (!std::isfinite(n.vox_offset) || n.vox_offset < minimum_offset ||
      n.vox_offset != std::floor(n.vox_offset) || n.vox_offset > double(uint64_t{1} << 40)) {
    return field_error(
        path, "vox_offset",
        cat("is ", show(n.vox_offset), "; it must be a whole number >= ", minimum_offset));
  }
  double slope = n.scl_slope, intercept = n.scl_inter;
  if (!std::isfinite(slope) || slope == 0) {
    slope = 1;
    intercept = 0;
  }
  if (!std::isfinite(intercept)) return field_error(path, "scl_inter", "is not finite");

  LABELMESH_ASSIGN_OR_RETURN(auto affine, nifti_affine(path, n));

  VolumeHeader header;
  header.format = ImageFormat::kNifti;
  header.scalar_type = type;
  header.big_endian = swap != (std::endian::native == std::endian::big);
  header.data_path = path;
  header.encoding = gzip ? DataEncoding::kGzip : DataEncoding::kRaw;
  const auto vox_offset = static_cast<uint64_t>(n.vox_offset);
  header.file_offset = gzip ? 0 : vox_offset;
  header.decoded_offset = gzip ? vox_offset : 0;
  header.rescale_slope = slope;
  header.rescale_intercept = intercept;

  ImageGeometry& g = header.geometry;
  g.dims = dims;
  // RAS -> LPS: negate the x and y rows.
  const double flip[3] = {-1, -1, 1};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      g.direction[3 * row + col] = flip[row] * affine[4 * row + col];
    g.origin[row] = flip[row] * affine[4 * row + 3];
  }
  for (int col = 0; col < 3; ++col) {
    g.spacing[col] = std::sqrt(g.direction[col] * g.direction[col] +
                               g.direction[3 + col] * g.direction[3 + col] +
                               g.direction[6 + col] * g.direction[6 + col]);
  }
  const char* field = n.sform_code > 0 ? "srow_x/srow_y/srow_z" : "pixdim";
  LABELMESH_RETURN_IF_ERROR(check_spacing(path, field, g.spacing));
  if (auto s = normalise_direction(path, n.sform_code > 0 ? "srow" : "quatern", g.direction);
      !s.ok()) {
    return s;
  }

  const uint64_t needed = header.data_bytes();
  auto payload = gzip ? check_encoded_payload(path, 0, DataEncoding::kGzip, 0, vox_offset + needed)
                      : check_raw_payload(path, vox_offset, needed);
  if (!payload.ok()) return payload;
  return header;
}

}  // namespace labelmesh::volume::internal
