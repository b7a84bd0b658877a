// SPDX-License-Identifier: AGPL-3.0-or-later
// DICOM SEG input on the shared SEGs of two independent writers (highdicom,
// dcmqi): each is read onto the right grid or refused with a clear reason.
#include "core/volume/read_dicom_seg.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <vtkPointData.h>

#include "absl/strings/match.h"
#include "core/header/dicom_seg_grid.h"
#include "core/volume/read_label_volume.h"
#include "core/volume/voxel_access.h"
#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh::volume {
namespace {

std::string seg_file(const std::string& name) { return testing::shared_data("dicom-seg/" + name); }

LabelVolume read_or_fail(const std::string& path, const ReadLimits& limits = {}) {
  auto volume = read_label_volume(path, limits, RunContext{});
  EXPECT_THAT(volume, testing::IsOk());
  return volume.ok() ? std::move(*volume) : LabelVolume{};
}

int64_t voxels_with(const LabelVolume& volume, int64_t label) {
  int64_t count = 0;
  visit_voxels(volume.voxels, [&](const auto* voxels, size_t n) {
    for (size_t i = 0; i < n; ++i) count += int64_t(voxels[i]) == label ? 1 : 0;
  });
  return count;
}

int64_t label_at(const LabelVolume& volume, const std::array<int64_t, 3>& index) {
  return std::llround(
      volume.voxels->GetScalarComponentAsDouble(int(index[0]), int(index[1]), int(index[2]), 0));
}

absl::Status refusal_of(const std::string& name) {
  return read_label_volume(seg_file(name), ReadLimits{}, RunContext{}).status();
}

TEST(DicomSeg, DcmqiSegAgreesWithItsLabelMapVoxelForVoxelInPatientSpace) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const LabelVolume seg = read_or_fail(seg_file("dcmqi-24x38x3-seg.dcm"));
  const LabelVolume map = read_or_fail(seg_file("dcmqi-24x38x3-label.nrrd"));
  ASSERT_EQ(seg.format, ImageFormat::kDicomSeg);
  EXPECT_EQ(seg.geometry.dims, (std::array<int64_t, 3>{24, 38, 3}));
  EXPECT_NEAR(seg.geometry.spacing[0], 0.7, 1e-9);
  EXPECT_NEAR(seg.geometry.spacing[2], 2.5, 1e-9);
  // Every voxel of the label map, found at its own patient position in the SEG.
  int64_t inside = 0, disagree = 0;
  const auto& dims = map.geometry.dims;
  for (int64_t k = 0; k < dims[2]; ++k) {
    for (int64_t j = 0; j < dims[1]; ++j) {
      for (int64_t i = 0; i < dims[0]; ++i) {
        const auto point = map.geometry.to_physical({double(i), double(j), double(k)});
        const auto at = seg.geometry.to_index(point);
        std::array<int64_t, 3> index{};
        for (int axis = 0; axis < 3; ++axis) {
          index[axis] = std::llround(at[axis]);
          ASSERT_NEAR(at[axis], double(index[axis]), 1e-3) << "voxel centres do not coincide";
          ASSERT_GE(index[axis], 0);
          ASSERT_LT(index[axis], seg.geometry.dims[axis]);
        }
        const bool in_map = label_at(map, {i, j, k}) != 0;
        const bool in_seg = label_at(seg, index) == 1;
        inside += in_map ? 1 : 0;
        disagree += in_map != in_seg ? 1 : 0;
      }
    }
  }
  // pydicom's pixel_array of the SEG also sums to 315.
  EXPECT_EQ(inside, 315);
  EXPECT_EQ(disagree, 0);
  EXPECT_EQ(voxels_with(seg, 1), 315);
}

TEST(DicomSeg, SegmentsBecomeLabelsWithNameColourAndCodes) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const LabelVolume seg = read_or_fail(seg_file("dcmqi-24x38x3-seg.dcm"));
  ASSERT_EQ(seg.descriptions.size(), 1u);
  const LabelDescription& liver = seg.descriptions[0];
  EXPECT_EQ(liver.label, 1);
  EXPECT_EQ(liver.name, "Liver");
  EXPECT_EQ(liver.type.meaning, "Liver");
  EXPECT_EQ(liver.type.value, "T-62000");
  ASSERT_TRUE(liver.colour.has_value());
  // Recommended Display CIELab 41661\41167\40792 is 3D Slicer's liver colour.
  EXPECT_EQ(*liver.colour, (std::array<uint8_t, 3>{221, 130, 101}));
  EXPECT_EQ(liver.category.meaning, "Tissue");
}

TEST(DicomSeg, ImplicitVrBinaryFramesWithoutSliceSpacingTakeTheirGaps) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const LabelVolume seg = read_or_fail(seg_file("highdicom-seg_image_ct_binary.dcm"));
  EXPECT_EQ(seg.geometry.dims, (std::array<int64_t, 3>{16, 16, 3}));
  EXPECT_NEAR(seg.geometry.spacing[2], 1.25, 1e-6);
  // Positions are stored as -125\-128.100006\103.019997.
  EXPECT_NEAR(seg.geometry.origin[0], -125, 1e-4);
  EXPECT_NEAR(seg.geometry.origin[1], -128.1, 1e-4);
  EXPECT_NEAR(seg.geometry.origin[2], 103.02, 1e-4);
  // As pydicom's pixel_array counts them.
  EXPECT_EQ(voxels_with(seg, 1), 638);
}

TEST(DicomSeg, OneFrameTakesItsSpacingFromTheHeader) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const LabelVolume seg = read_or_fail(seg_file("highdicom-seg_image_ct_binary_single_frame.dcm"));
  EXPECT_EQ(seg.geometry.dims, (std::array<int64_t, 3>{128, 128, 1}));
  EXPECT_NEAR(seg.geometry.spacing[2], 5.0, 1e-9);
  EXPECT_EQ(voxels_with(seg, 1), 1832);  // pydicom: 1832
}

TEST(DicomSeg, FractionalPixelsAreInsideFromTheThreshold) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string path = seg_file("highdicom-seg_image_ct_binary_fractional.dcm");
  ReadLimits any_value, half, whole;
  any_value.fractional_threshold = 1e-9;
  whole.fractional_threshold = 1.0;
  const int64_t nonzero = voxels_with(read_or_fail(path, any_value), 1);
  const int64_t at_half = voxels_with(read_or_fail(path, half), 1);
  const int64_t at_max = voxels_with(read_or_fail(path, whole), 1);
  // DCMTK's own frames hold 127, 256 and 255 non-zero bytes, one a pixel.
  EXPECT_EQ(nonzero, 127 + 256 + 255);
  EXPECT_LE(at_max, at_half);
  EXPECT_LE(at_half, nonzero);
  EXPECT_GT(at_max, 0);
}

TEST(DicomSeg, OverlappingSegmentsAreAnErrorNamingThem) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const absl::Status status = refusal_of("highdicom-seg_image_ct_binary_overlap.dcm");
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  // pydicom: the two segments' frames share 16 pixels.
  EXPECT_TRUE(absl::StrContains(status.message(), "segments 1 and 2 share 16 voxels")) << status;
  EXPECT_TRUE(absl::StrContains(status.message(), "highdicom-seg_image_ct_binary_overlap.dcm"))
      << status;
  EXPECT_TRUE(absl::StrContains(status.message(), "--overlapping separate")) << status;
}

int64_t voxels_with(vtkImageData* image, int64_t label) {
  int64_t count = 0;
  visit_voxels(image, [&](const auto* voxels, size_t n) {
    for (size_t i = 0; i < n; ++i) count += int64_t(voxels[i]) == label ? 1 : 0;
  });
  return count;
}

// Bits set in each segment's frames, counted from the Pixel Data bytes as
// pydicom's pixel_array would sum them, without the reader.
std::map<int64_t, int64_t> bits_per_segment(const std::string& path) {
  auto header = internal::parse_dicom_seg_header(path);
  EXPECT_THAT(header, testing::IsOk());
  if (!header.ok()) return {};
  EXPECT_EQ(header->bits_allocated, 1);
  const std::string bytes = testing::read_bytes(path);
  const uint64_t frame_pixels = uint64_t(header->rows) * header->columns;
  std::map<int64_t, int64_t> bits;
  for (uint32_t f = 0; f < header->frames; ++f) {
    for (uint64_t p = 0; p < frame_pixels; ++p) {
      const uint64_t at = f * frame_pixels + p;
      const auto byte = static_cast<uint8_t>(bytes.at(header->pixel_data_offset + at / 8));
      bits[header->frame_segments[f]] += (byte >> (at % 8)) & 1;
    }
  }
  return bits;
}

std::vector<vtkImageData*> images_of(const LabelVolume& volume) {
  std::vector<vtkImageData*> images{volume.voxels};
  for (const auto& layer : volume.more_layers) images.push_back(layer);
  return images;
}

TEST(DicomSeg, OverlappingSegmentsKeptApartLieWholeInLayersOfTheirOwn) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string path = seg_file("highdicom-seg_image_ct_binary_overlap.dcm");
  ReadLimits limits;
  limits.separate_overlapping = true;
  const LabelVolume seg = read_or_fail(path, limits);
  ASSERT_EQ(seg.more_layers.size(), 1u);
  const std::map<int64_t, int64_t> expected = bits_per_segment(path);
  ASSERT_EQ(expected.size(), 2u);
  // Segment 1: four frames of 16 pixels; segment 2: four of 4, all in segment 1.
  EXPECT_EQ(expected.at(1), 64);
  EXPECT_EQ(expected.at(2), 16);
  // Segment 1 first, in the voxels; segment 2 overlaps it, so in the next.
  const auto images = images_of(seg);
  EXPECT_EQ(voxels_with(images[0], 1), expected.at(1));
  EXPECT_EQ(voxels_with(images[0], 2), 0);
  EXPECT_EQ(voxels_with(images[1], 1), 0);
  EXPECT_EQ(voxels_with(images[1], 2), expected.at(2));
  for (vtkImageData* image : images) {
    int dims[3];
    image->GetDimensions(dims);
    EXPECT_EQ((std::array<int64_t, 3>{dims[0], dims[1], dims[2]}), seg.geometry.dims);
    EXPECT_EQ(image->GetScalarType(), seg.voxels->GetScalarType());
  }
  // Together the layers cover both segments, the 16 shared voxels once.
  const auto count = static_cast<size_t>(seg.geometry.voxel_count());
  std::vector<uint8_t> covered(count, 0);
  for (vtkImageData* image : images) {
    visit_voxels(image, [&](const auto* voxels, size_t n) {
      for (size_t i = 0; i < std::min(n, count); ++i) covered[i] |= voxels[i] != 0;
    });
  }
  EXPECT_EQ(std::count(covered.begin(), covered.end(), 1), expected.at(1) + expected.at(2) - 16);
  ASSERT_EQ(seg.descriptions.size(), 2u);
  EXPECT_EQ(seg.descriptions[1].label, 2);
}

TEST(DicomSeg, KeepingOverlapsApartChangesNothingWhenNothingOverlaps) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ReadLimits separate;
  separate.separate_overlapping = true;
  for (const char* name : {"dcmqi-24x38x3-seg.dcm", "highdicom-seg_image_ct_binary.dcm"}) {
    const LabelVolume plain = read_or_fail(seg_file(name));
    const LabelVolume kept = read_or_fail(seg_file(name), separate);
    EXPECT_TRUE(kept.more_layers.empty()) << name;
    vtkDataArray* a = plain.voxels->GetPointData()->GetScalars();
    vtkDataArray* b = kept.voxels->GetPointData()->GetScalars();
    ASSERT_EQ(a->GetDataType(), b->GetDataType()) << name;
    ASSERT_EQ(a->GetNumberOfTuples(), b->GetNumberOfTuples()) << name;
    EXPECT_EQ(std::memcmp(a->GetVoidPointer(0), b->GetVoidPointer(0),
                          size_t(a->GetNumberOfTuples()) * size_t(a->GetDataTypeSize())),
              0)
        << name;
  }
}

TEST(DicomSeg, LayersKeptApartCountAgainstTheVoxelLimit) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string path = seg_file("highdicom-seg_image_ct_binary_overlap.dcm");
  ReadLimits limits;
  limits.separate_overlapping = true;
  limits.max_voxels = 16 * 16 * 165;  // one layer, not two
  const absl::Status status = read_label_volume(path, limits, RunContext{}).status();
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(status.message(), "highdicom-seg_image_ct_binary_overlap.dcm"))
      << status;
  EXPECT_TRUE(absl::StrContains(status.message(), "2 layers of 42240 voxels")) << status;
  EXPECT_TRUE(absl::StrContains(status.message(), "exceeds the limit of 42240")) << status;
  limits.max_voxels = 2 * 16 * 16 * 165;
  EXPECT_THAT(read_label_volume(path, limits, RunContext{}), testing::IsOk());
}

TEST(DicomSeg, SparseFramesLandOnTheSliceGridAcrossTheGap) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  // Frames at z -99.48 and 103.02 to 105.52 mm, 1.25 mm apart: 165 slices.
  auto header = check_volume_header(seg_file("highdicom-seg_image_ct_binary_overlap.dcm"));
  ASSERT_THAT(header, testing::IsOk());
  EXPECT_EQ(header->geometry.dims, (std::array<int64_t, 3>{16, 16, 165}));
  EXPECT_NEAR(header->geometry.origin[2], -99.48, 1e-4);
}

TEST(DicomSeg, WhatHasNoPatientSpaceVolumeIsRefusedSayingWhy) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const absl::Status radiograph = refusal_of("highdicom-seg_image_cr_binary.dcm");
  EXPECT_THAT(radiograph, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(radiograph.message(), "no 3D patient-space geometry"))
      << radiograph;
  const absl::Status slide = refusal_of("highdicom-seg_image_sm_control.dcm");
  EXPECT_THAT(slide, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(slide.message(), "slide microscopy")) << slide;
  const absl::Status label_map = refusal_of("dcmqi-sparse-labelmap-noppv.dcm");
  EXPECT_THAT(label_map, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(label_map.message(), "Label Map Segmentation Storage"))
      << label_map;
}

// DCMTK finds segment n as the n-th item; a file numbered otherwise would
// put names on the wrong labels, so it is refused.
TEST(DicomSeg, SegmentsNumberedOutOfOrderAreRefused) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string path = seg_file("dcmqi-24x38x3-seg.dcm");
  auto header = internal::parse_dicom_seg_header(path);
  ASSERT_THAT(header, testing::IsOk());
  ASSERT_THAT(dicom_seg_grid(path, *header, ReadLimits{}), testing::IsOk());
  header->segment_numbers = {2};
  header->frame_segments = {2, 2, 2};
  const absl::Status status = dicom_seg_grid(path, *header, ReadLimits{}).status();
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(status.message(), "numbered 1, 2, 3")) << status;
}

TEST(DicomSeg, TheVoxelLimitHoldsBeforeAnythingIsRead) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  ReadLimits tiny;
  tiny.max_voxels = 24 * 38 * 3 - 1;
  const auto status =
      read_label_volume(seg_file("dcmqi-24x38x3-seg.dcm"), tiny, RunContext{}).status();
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_TRUE(absl::StrContains(status.message(), "exceeds the limit of 2735")) << status;
}

}  // namespace
}  // namespace labelmesh::volume
