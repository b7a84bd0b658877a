// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/read_label_volume.h"

#include <bit>
#include <cmath>
#include <limits>

#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNIFTIImageReader.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataReader.h>

#include "core/header/header_checks.h"
#include "core/header/payload_stream.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/volume/merge_slicer_layers.h"
#include "core/volume/read_dicom_seg.h"
#include "core/volume/vtk_error_flag.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

int vtk_type_of(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
      return VTK_SIGNED_CHAR;
    case ScalarType::kUInt8:
      return VTK_UNSIGNED_CHAR;
    case ScalarType::kInt16:
      return VTK_SHORT;
    case ScalarType::kUInt16:
      return VTK_UNSIGNED_SHORT;
    case ScalarType::kInt32:
      return VTK_INT;
    case ScalarType::kUInt32:
      return VTK_UNSIGNED_INT;
    case ScalarType::kInt64:
      return VTK_TYPE_INT64;
    case ScalarType::kUInt64:
      return VTK_TYPE_UINT64;
    case ScalarType::kFloat32:
      return VTK_FLOAT;
    case ScalarType::kFloat64:
      return VTK_DOUBLE;
  }
  return VTK_VOID;
}

// Runs a VTK reader; false when it reported any error.
bool run_reader(vtkAlgorithm* reader) {
  vtkNew<VtkErrorFlag> flag;
  reader->AddObserver(vtkCommand::ErrorEvent, flag);
  reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, flag);
  reader->Update();
  return !flag->raised;
}

struct DecodedVoxels {
  vtkSmartPointer<vtkDataArray> array;
  // The reader stored voxel axis 2 in reverse order (NIfTI qfac = -1).
  bool reversed_k = false;
};

absl::StatusOr<DecodedVoxels> read_with_vtk(const std::string& path, const VolumeHeader& header) {
  DecodedVoxels decoded;
  vtkImageData* image = nullptr;
  vtkSmartPointer<vtkAlgorithm> keep;
  if (header.format == ImageFormat::kNifti) {
    auto reader = vtkSmartPointer<vtkNIFTIImageReader>::New();
    reader->SetFileName(path.c_str());
    if (!run_reader(reader)) return field_error(path, "voxel data", "could not be decoded");
    decoded.reversed_k = reader->GetQFac() < 0;
    image = reader->GetOutput();
    keep = reader;
  } else {
    auto reader = vtkSmartPointer<vtkXMLImageDataReader>::New();
    reader->SetFileName(path.c_str());
    if (!run_reader(reader)) return field_error(path, "voxel data", "could not be decoded");
    image = reader->GetOutput();
    keep = reader;
  }
  vtkDataArray* array = image->GetPointData()->GetScalars();
  if (array == nullptr && image->GetPointData()->GetNumberOfArrays() > 0) {
    array = image->GetPointData()->GetArray(0);
  }
  if (array == nullptr) return field_error(path, "voxel data", "holds no voxel array");
  int dims[3];
  image->GetDimensions(dims);
  for (int axis = 0; axis < 3; ++axis) {
    if (dims[axis] != header.geometry.dims[axis]) {
      return field_error(path, "voxel data", "does not have the dimensions the header declares");
    }
  }
  decoded.array = array;
  return decoded;
}

// Our reader for INR, NRRD and MetaImage: one contiguous block, raw, gzip or
// zlib; header.layers values a voxel (a layered Slicer segmentation).
absl::StatusOr<DecodedVoxels> read_block(const std::string& path, const VolumeHeader& header) {
  LABELMESH_ASSIGN_OR_RETURN(
      auto stream, internal::PayloadStream::open(header.data_path, header.file_offset,
                                                 header.encoding, header.compressed_bytes));
  if (auto skipped = stream->skip(header.decoded_offset);
      !skipped.ok() || *skipped != header.decoded_offset) {
    return field_error(path, "voxel data", "is missing");
  }
  vtkSmartPointer<vtkDataArray> array;
  array.TakeReference(vtkDataArray::CreateDataArray(vtk_type_of(header.scalar_type)));
  array->SetNumberOfComponents(1);
  array->SetNumberOfTuples(header.geometry.voxel_count() * header.layers);
  const uint64_t bytes = header.data_bytes();
  LABELMESH_ASSIGN_OR_RETURN(auto got,
                             stream->read(static_cast<char*>(array->GetVoidPointer(0)), bytes));
  if (got != bytes) {
    return field_error(path, "voxel data",
                       cat("is truncated: expected ", bytes, " bytes, found ", got));
  }
  const bool swap = header.big_endian != (std::endian::native == std::endian::big);
  const int size = scalar_size(header.scalar_type);
  if (swap && size > 1) {
    auto* p = static_cast<unsigned char*>(array->GetVoidPointer(0));
    for (uint64_t i = 0; i < bytes; i += static_cast<uint64_t>(size)) {
      for (int b = 0; b < size / 2; ++b) std::swap(p[i + b], p[i + size - 1 - b]);
    }
  }
  return DecodedVoxels{array, false};
}

bool kept_in_memory(int vtk_type) {
  return vtk_type == VTK_SIGNED_CHAR || vtk_type == VTK_CHAR || vtk_type == VTK_UNSIGNED_CHAR ||
         vtk_type == VTK_SHORT || vtk_type == VTK_UNSIGNED_SHORT || vtk_type == VTK_INT;
}

template <typename T>
absl::Status convert_to_int32(const std::string& path, const T* source, int32_t* target,
                              size_t count, double slope, double intercept) {
  constexpr double kLow = std::numeric_limits<int32_t>::min();
  constexpr double kHigh = std::numeric_limits<int32_t>::max();
  for (size_t i = 0; i < count; ++i) {
    const double value = static_cast<double>(source[i]) * slope + intercept;
    if (!(value >= kLow && value <= kHigh)) {
      return field_error(
          path, "voxel data",
          cat("voxel ", i, " holds ", internal::show(value), ", outside the int32 label range"));
    }
    if (value != std::floor(value)) {
      return field_error(path, "voxel data",
                         cat("voxel ", i, " holds ", internal::show(value),
                             "; real-valued volumes must hold whole-number labels"));
    }
    target[i] = static_cast<int32_t>(value);
  }
  return absl::OkStatus();
}

absl::StatusOr<vtkSmartPointer<vtkDataArray>> to_label_array(const std::string& path,
                                                             const VolumeHeader& header,
                                                             vtkDataArray* array) {
  const bool rescaled = header.rescale_slope != 1.0 || header.rescale_intercept != 0.0;
  if (kept_in_memory(array->GetDataType()) && !rescaled)
    return vtkSmartPointer<vtkDataArray>(array);
  auto labels = vtkSmartPointer<vtkIntArray>::New();
  labels->SetNumberOfComponents(1);
  labels->SetNumberOfTuples(array->GetNumberOfTuples());
  const auto count = static_cast<size_t>(array->GetNumberOfTuples());
  absl::Status status = absl::InternalError("unsupported voxel type");
  switch (array->GetDataType()) {
    vtkTemplateMacro(status = convert_to_int32(path,
                                               static_cast<const VTK_TT*>(array->GetVoidPointer(0)),
                                               labels->GetPointer(0), count, header.rescale_slope,
                                               header.rescale_intercept));
  }
  if (!status.ok()) return status;
  return vtkSmartPointer<vtkDataArray>(labels);
}

}  // namespace

absl::StatusOr<LabelVolume> read_label_volume(const std::string& path, const ReadLimits& limits,
                                              const RunContext& context) {
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  if (format_of_file(path) == ImageFormat::kDicomSeg) return read_dicom_seg(path, limits, context);
  LABELMESH_ASSIGN_OR_RETURN(auto header, check_volume_header(path, limits));
  context.report("read", 0.1);

  const bool own_reader = header.format == ImageFormat::kInr ||
                          header.format == ImageFormat::kNrrd ||
                          header.format == ImageFormat::kMetaImage;
  LABELMESH_ASSIGN_OR_RETURN(auto decoded,
                             own_reader ? read_block(path, header) : read_with_vtk(path, header));
  if (decoded.array->GetNumberOfComponents() != 1 ||
      decoded.array->GetNumberOfTuples() != header.geometry.voxel_count() * header.layers) {
    return field_error(path, "voxel data", "does not hold one value per voxel");
  }
  LABELMESH_RETURN_IF_ERROR(context.check_stop());
  LABELMESH_ASSIGN_OR_RETURN(auto labels, to_label_array(path, header, decoded.array));

  LabelVolume volume;
  if (!header.segments.empty()) {
    LABELMESH_ASSIGN_OR_RETURN(auto slicer,
                               merge_slicer_layers(path, header, labels, limits, context));
    labels = slicer.voxels;
    volume.descriptions = std::move(slicer.descriptions);
    for (const auto& layer : slicer.more_layers) {
      auto image = vtkSmartPointer<vtkImageData>::New();
      image->SetDimensions(static_cast<int>(header.geometry.dims[0]),
                           static_cast<int>(header.geometry.dims[1]),
                           static_cast<int>(header.geometry.dims[2]));
      image->GetPointData()->SetScalars(layer);
      volume.more_layers.push_back(std::move(image));
    }
  }
  volume.format = header.format;
  volume.file_voxel_type = std::string(scalar_type_name(header.scalar_type));
  volume.geometry = header.geometry;
  if (decoded.reversed_k) volume.geometry.reverse_axis(2);
  volume.voxels = vtkSmartPointer<vtkImageData>::New();
  volume.voxels->SetDimensions(static_cast<int>(header.geometry.dims[0]),
                               static_cast<int>(header.geometry.dims[1]),
                               static_cast<int>(header.geometry.dims[2]));
  volume.voxels->GetPointData()->SetScalars(labels);
  context.report("read", 1.0);
  return volume;
}

}  // namespace labelmesh::volume
