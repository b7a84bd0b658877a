// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/write_label_volume.h"

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataWriter.h>

#include "core/header/volume_header.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/vtk_error_flag.h"

namespace labelmesh::volume {
namespace {

struct TypeNames {
  int vtk_type;
  std::string_view metaimage, nrrd, inr_type;
  int bits;
};

const TypeNames* type_names(int vtk_type) {
  static constexpr TypeNames kNames[] = {
      {VTK_SIGNED_CHAR, "MET_CHAR", "int8", "signed fixed", 8},
      {VTK_CHAR, "MET_CHAR", "int8", "signed fixed", 8},
      {VTK_UNSIGNED_CHAR, "MET_UCHAR", "uint8", "unsigned fixed", 8},
      {VTK_SHORT, "MET_SHORT", "int16", "signed fixed", 16},
      {VTK_UNSIGNED_SHORT, "MET_USHORT", "uint16", "unsigned fixed", 16},
      {VTK_INT, "MET_INT", "int32", "signed fixed", 32}};
  for (const auto& names : kNames) {
    if (names.vtk_type == vtk_type) return &names;
  }
  return nullptr;
}

std::string numbers(std::initializer_list<double> values, std::string_view separator = " ") {
  std::string text;
  for (double v : values) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    text += cat(text.empty() ? "" : separator, buffer);
  }
  return text;
}

absl::Status io_error(const std::string& path) {
  return absl::InternalError(cat(path, ": could not write the file"));
}

absl::Status write_bytes(const std::string& path, const std::string& header, const void* data,
                         size_t bytes, bool gzip) {
  if (gzip) {
    gzFile file = gzopen(path.c_str(), "wb6");
    if (file == nullptr) return io_error(path);
    bool ok = gzwrite(file, header.data(), static_cast<unsigned>(header.size())) ==
              static_cast<int>(header.size());
    const char* p = static_cast<const char*>(data);
    for (size_t done = 0; ok && done < bytes;) {
      const auto n = static_cast<unsigned>(std::min<size_t>(bytes - done, size_t{1} << 30));
      ok = gzwrite(file, p + done, n) == static_cast<int>(n);
      done += n;
    }
    return gzclose(file) == Z_OK && ok ? absl::OkStatus() : io_error(path);
  }
  std::ofstream out(path, std::ios::binary);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  return out ? absl::OkStatus() : io_error(path);
}

// "stem.raw" beside a detached header.
std::string raw_name_for(const std::string& path) {
  return std::filesystem::path(path).stem().string() + ".raw";
}

absl::Status write_metaimage(const LabelVolume& volume, const std::string& path, bool detached,
                             const TypeNames& names, vtkDataArray* array) {
  const auto& g = volume.geometry;
  const auto& d = g.direction;
  std::ostringstream h;
  h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
    << "CompressedData = False\n"
    // Axis 0's direction first, then axis 1, then axis 2 (as ITK reads it).
    << "TransformMatrix = " << numbers({d[0], d[3], d[6], d[1], d[4], d[7], d[2], d[5], d[8]})
    << "\n"
    << "Offset = " << numbers({g.origin[0], g.origin[1], g.origin[2]}) << "\n"
    << "AnatomicalOrientation = RAI\n"
    << "ElementSpacing = " << numbers({g.spacing[0], g.spacing[1], g.spacing[2]}) << "\n"
    << "DimSize = " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2] << "\n"
    << "ElementType = " << names.metaimage << "\n";
  const size_t bytes = static_cast<size_t>(array->GetNumberOfTuples()) * array->GetDataTypeSize();
  if (!detached) {
    h << "ElementDataFile = LOCAL\n";
    return write_bytes(path, h.str(), array->GetVoidPointer(0), bytes, false);
  }
  const std::string raw = raw_name_for(path);
  h << "ElementDataFile = " << raw << "\n";
  LABELMESH_RETURN_IF_ERROR(write_bytes(path, h.str(), nullptr, 0, false));
  const auto raw_path = (std::filesystem::path(path).parent_path() / raw).string();
  return write_bytes(raw_path, "", array->GetVoidPointer(0), bytes, false);
}

absl::Status write_nrrd(const LabelVolume& volume, const std::string& path, bool detached,
                        const TypeNames& names, vtkDataArray* array) {
  const auto& g = volume.geometry;
  const auto& d = g.direction;
  auto axis = [&](int c) {
    return cat(
        "(", numbers({d[c] * g.spacing[c], d[3 + c] * g.spacing[c], d[6 + c] * g.spacing[c]}, ","),
        ")");
  };
  std::ostringstream h;
  h << "NRRD0004\n# written by labelmesh\ntype: " << names.nrrd << "\ndimension: 3\n"
    << "space: left-posterior-superior\n"
    << "sizes: " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2] << "\n"
    << "space directions: " << axis(0) << " " << axis(1) << " " << axis(2) << "\n"
    << "kinds: domain domain domain\nendian: little\nencoding: raw\n"
    << "space origin: (" << numbers({g.origin[0], g.origin[1], g.origin[2]}, ",") << ")\n";
  const size_t bytes = static_cast<size_t>(array->GetNumberOfTuples()) * array->GetDataTypeSize();
  if (!detached) {
    h << "\n";
    return write_bytes(path, h.str(), array->GetVoidPointer(0), bytes, false);
  }
  const std::string raw = raw_name_for(path);
  h << "data file: " << raw << "\n";
  LABELMESH_RETURN_IF_ERROR(write_bytes(path, h.str(), nullptr, 0, false));
  const auto raw_path = (std::filesystem::path(path).parent_path() / raw).string();
  return write_bytes(raw_path, "", array->GetVoidPointer(0), bytes, false);
}

absl::Status write_inr(const LabelVolume& volume, const std::string& path, bool gzip,
                       const TypeNames& names, vtkDataArray* array) {
  const auto& g = volume.geometry;
  const std::array<double, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int i = 0; i < 9; ++i) {
    if (std::abs(g.direction[i] - identity[i]) > 1e-9) {
      return absl::InvalidArgumentError(
          cat(path,
              ": INR cannot store an oblique or flipped grid; use NIfTI, MetaImage, NRRD or VTI"));
    }
  }
  std::ostringstream h;
  h << "#INRIMAGE-4#{\nXDIM=" << g.dims[0] << "\nYDIM=" << g.dims[1] << "\nZDIM=" << g.dims[2]
    << "\nVDIM=1\nTYPE=" << names.inr_type << "\nPIXSIZE=" << names.bits << " bits\nSCALE=2**0\n"
    << "CPU=decm\nVX=" << numbers({g.spacing[0]}) << "\nVY=" << numbers({g.spacing[1]})
    << "\nVZ=" << numbers({g.spacing[2]}) << "\nTX=" << numbers({g.origin[0]})
    << "\nTY=" << numbers({g.origin[1]}) << "\nTZ=" << numbers({g.origin[2]}) << "\n";
  std::string header = h.str();
  const size_t padded = (header.size() + 4 + 255) / 256 * 256;
  header.append(padded - 4 - header.size(), '\n');
  header += "##}\n";
  const size_t bytes = static_cast<size_t>(array->GetNumberOfTuples()) * array->GetDataTypeSize();
  return write_bytes(path, header, array->GetVoidPointer(0), bytes, gzip);
}

// A copy of the voxels' image placed with spacing (and, for VTI, direction).
vtkSmartPointer<vtkImageData> placed_image(const LabelVolume& volume, bool with_placement) {
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->ShallowCopy(volume.voxels);
  const auto& g = volume.geometry;
  image->SetSpacing(g.spacing[0], g.spacing[1], g.spacing[2]);
  image->SetOrigin(0, 0, 0);
  if (with_placement) {
    image->SetOrigin(g.origin[0], g.origin[1], g.origin[2]);
    image->SetDirectionMatrix(g.direction.data());
  }
  return image;
}

absl::Status write_nifti(const LabelVolume& volume, const std::string& path) {
  const auto& g = volume.geometry;
  // Voxel coordinates x spacing -> RAS: LPS direction and origin with x, y negated.
  vtkNew<vtkMatrix4x4> to_ras;
  const double flip[3] = {-1, -1, 1};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      to_ras->SetElement(row, col, flip[row] * g.direction[3 * row + col]);
    to_ras->SetElement(row, 3, flip[row] * g.origin[row]);
  }
  vtkNew<vtkNIFTIImageWriter> writer;
  writer->SetInputData(placed_image(volume, false));
  writer->SetFileName(path.c_str());
  writer->SetSFormMatrix(to_ras);
  if (to_ras->Determinant() > 0) writer->SetQFormMatrix(to_ras);
  vtkNew<VtkErrorFlag> flag;
  writer->AddObserver(vtkCommand::ErrorEvent, flag);
  writer->Write();
  return flag->raised ? io_error(path) : absl::OkStatus();
}

absl::Status write_vti(const LabelVolume& volume, const std::string& path) {
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(placed_image(volume, true));
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToZLib();
  vtkNew<VtkErrorFlag> flag;
  writer->AddObserver(vtkCommand::ErrorEvent, flag);
  return writer->Write() == 1 && !flag->raised ? absl::OkStatus() : io_error(path);
}

}  // namespace

absl::Status write_label_volume(const LabelVolume& volume, const std::string& path) {
  auto format = format_from_path(path);
  if (!format) {
    return absl::InvalidArgumentError(cat(path, ": unknown volume file extension"));
  }
  vtkDataArray* array = volume.voxels->GetPointData()->GetScalars();
  const TypeNames* names = array ? type_names(array->GetDataType()) : nullptr;
  if (names == nullptr) return absl::InvalidArgumentError("the volume holds no integer voxels");
  const std::string lower = to_lower(path);
  switch (*format) {
    case ImageFormat::kNifti:
      return write_nifti(volume, path);
    case ImageFormat::kMetaImage:
      return write_metaimage(volume, path, std::string_view(lower).ends_with(".mhd"), *names,
                             array);
    case ImageFormat::kNrrd:
      return write_nrrd(volume, path, std::string_view(lower).ends_with(".nhdr"), *names, array);
    case ImageFormat::kInr:
      return write_inr(volume, path, std::string_view(lower).ends_with(".gz"), *names, array);
    case ImageFormat::kVti:
      return write_vti(volume, path);
    case ImageFormat::kDicomSeg:
      return absl::InvalidArgumentError(
          cat(path, ": writing DICOM SEG is not supported; use .nrrd, .nii.gz or .mha"));
  }
  return absl::InternalError("unhandled image format");
}

}  // namespace labelmesh::volume
