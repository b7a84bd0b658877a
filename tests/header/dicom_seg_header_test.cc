// SPDX-License-Identifier: AGPL-3.0-or-later
// The DICOM SEG header walk: the real dcmqi and highdicom files read as DCMTK
// reads them, and broken or hostile files are errors that name the element,
// never crashes.
#include "core/header/dicom_seg_header.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "support/status_matchers.h"
#include "support/test_files.h"

namespace labelmesh {
namespace {

using volume::internal::DicomSegHeader;
using volume::internal::parse_dicom_seg_header;

std::string seg_file(std::string_view name) {
  return testing::shared_data(std::string("dicom-seg/") + std::string(name));
}

DicomSegHeader parse_ok(const std::string& path) {
  auto header = parse_dicom_seg_header(path);
  EXPECT_THAT(header, testing::IsOk());
  return header.ok() ? *std::move(header) : DicomSegHeader{};
}

// The status of parsing `bytes` written to a scratch file.
absl::Status parse_bytes(const std::filesystem::path& dir, std::string_view bytes,
                         uint64_t max_header_bytes = uint64_t{64} << 20) {
  const auto path = dir / "seg.dcm";
  testing::write_file(path, bytes);
  return parse_dicom_seg_header(path.string(), max_header_bytes).status();
}

void expect_invalid(const absl::Status& status, std::string_view field, std::string_view problem) {
  EXPECT_THAT(status, testing::StatusIs(absl::StatusCode::kInvalidArgument)) << status;
  EXPECT_NE(status.message().find(std::string(field)), std::string::npos) << status;
  EXPECT_NE(status.message().find(std::string(problem)), std::string::npos) << status;
}

// Offsets in dcmqi-24x38x3-seg.dcm (explicit VR little endian).
constexpr size_t kDcmqiTransferSyntaxValue = 260;
constexpr size_t kDcmqiRowsValue = 1872;
constexpr size_t kDcmqiBitsAllocatedValue = 1892;
constexpr size_t kDcmqiNumberOfFramesValue = 1862;
constexpr size_t kDcmqiSharedGroupsLength = 2250;
constexpr size_t kDcmqiFirstPositionValue = 2856;
constexpr size_t kDcmqiPixelDataLength = 3838;
constexpr size_t kDcmqiPixelDataValue = 3842;

// Offset of Rows' length in highdicom-seg_image_ct_binary.dcm (implicit VR).
constexpr size_t kCtRowsLength = 2304;

void put_u16(std::string& bytes, size_t offset, uint16_t value) {
  bytes[offset] = static_cast<char>(value & 0xFF);
  bytes[offset + 1] = static_cast<char>(value >> 8);
}

void put_u32(std::string& bytes, size_t offset, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<char>(value >> (8 * i));
}

// A tag as written little endian, then `rest` (an explicit VR, say).
std::string tag_bytes(uint16_t group, uint16_t element, std::string_view rest) {
  std::string bytes(4, '\0');
  put_u16(bytes, 0, group);
  put_u16(bytes, 2, element);
  return bytes + std::string(rest);
}

// dcmqi-24x38x3-seg.dcm, after checking that the offsets above still hold
// the elements they name, so the byte edits below land where they should.
std::string dcmqi_bytes() {
  std::string bytes = testing::read_bytes(seg_file("dcmqi-24x38x3-seg.dcm"));
  const std::pair<size_t, std::string> tags[] = {
      {kDcmqiTransferSyntaxValue - 8, tag_bytes(0x0002, 0x0010, "UI")},
      {kDcmqiNumberOfFramesValue - 8, tag_bytes(0x0028, 0x0008, "IS")},
      {kDcmqiRowsValue - 8, tag_bytes(0x0028, 0x0010, "US")},
      {kDcmqiBitsAllocatedValue - 8, tag_bytes(0x0028, 0x0100, "US")},
      {kDcmqiSharedGroupsLength - 8, tag_bytes(0x5200, 0x9229, "SQ")},
      {kDcmqiFirstPositionValue - 8, tag_bytes(0x0020, 0x0032, "DS")},
      {kDcmqiPixelDataLength - 8, tag_bytes(0x7FE0, 0x0010, "OB")}};
  for (const auto& [offset, tag] : tags) {
    EXPECT_EQ(bytes.substr(offset, tag.size()), tag) << "at byte " << offset;
  }
  return bytes;
}

// Data elements in one of the three native transfer syntaxes, with sequences
// and items of defined (back-patched) or undefined length.
class DataSetWriter {
 public:
  DataSetWriter(bool explicit_vr, bool big_endian, bool undefined_lengths)
      : explicit_(explicit_vr), big_(big_endian), undefined_(undefined_lengths) {}

  void element(uint16_t group, uint16_t element, std::string_view vr, std::string value) {
    if (value.size() % 2 != 0) value.push_back(vr == "UI" ? '\0' : ' ');
    header(group, element, vr, static_cast<uint32_t>(value.size()));
    bytes_ += value;
  }
  void us(uint16_t group, uint16_t element, uint16_t value) {
    header(group, element, "US", 2);
    number(value, 2);
  }
  void begin_sequence(uint16_t group, uint16_t element) {
    header(group, element, "SQ", 0xFFFFFFFF);
    open_.push_back(bytes_.size() - 4);
  }
  void end_sequence() { close(0xE0DD); }
  void begin_item() {
    header(0xFFFE, 0xE000, "", 0xFFFFFFFF);
    open_.push_back(bytes_.size() - 4);
  }
  void end_item() { close(0xE00D); }
  const std::string& bytes() const { return bytes_; }

 private:
  void number(uint32_t value, int size) {
    for (int i = 0; i < size; ++i) {
      const int shift = 8 * (big_ ? size - 1 - i : i);
      bytes_.push_back(static_cast<char>((value >> shift) & 0xFF));
    }
  }
  void header(uint16_t group, uint16_t element, std::string_view vr, uint32_t length) {
    number(group, 2);
    number(element, 2);
    if (!explicit_ || group == 0xFFFE) {
      number(length, 4);
    } else if (vr == "SQ" || vr == "OB") {
      bytes_ += vr;
      number(0, 2);
      number(length, 4);
    } else {
      bytes_ += vr;
      number(length, 2);
    }
  }
  void close(uint16_t delimiter) {
    const size_t length_at = open_.back();
    open_.pop_back();
    if (undefined_) {
      header(0xFFFE, delimiter, "", 0);
      return;
    }
    const auto length = static_cast<uint32_t>(bytes_.size() - length_at - 4);
    for (int i = 0; i < 4; ++i) {
      const int shift = 8 * (big_ ? 3 - i : i);
      bytes_[length_at + i] = static_cast<char>((length >> shift) & 0xFF);
    }
  }

  bool explicit_, big_, undefined_;
  std::string bytes_;
  std::vector<size_t> open_;
};

// Preamble, "DICM" and a File Meta group naming `transfer_syntax`.
std::string part10(std::string_view transfer_syntax, std::string_view data_set) {
  DataSetWriter meta(true, false, false);
  meta.element(0x0002, 0x0010, "UI", std::string(transfer_syntax));
  return std::string(128, '\0') + "DICM" + meta.bytes() + std::string(data_set);
}

// A two-frame, two-segment SEG with every field the walk reads.
std::string synthetic_seg(std::string_view transfer_syntax, bool explicit_vr, bool big_endian,
                          bool undefined_lengths) {
  DataSetWriter w(explicit_vr, big_endian, undefined_lengths);
  w.element(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.66.4");
  w.element(0x0020, 0x9311, "CS", "TILED_FULL");
  w.element(0x0028, 0x0008, "IS", "2");
  w.us(0x0028, 0x0010, 2);
  w.us(0x0028, 0x0011, 3);
  w.us(0x0028, 0x0100, 8);
  w.element(0x0062, 0x0001, "CS", "FRACTIONAL");
  w.begin_sequence(0x0062, 0x0002);
  for (uint16_t segment : {7, 9}) {
    w.begin_item();
    w.element(0x0062, 0x0005, "LO", "label");
    w.us(0x0062, 0x0004, segment);
    w.end_item();
  }
  w.end_sequence();
  w.us(0x0062, 0x000E, 200);
  w.begin_sequence(0x5200, 0x9229);
  w.begin_item();
  w.begin_sequence(0x0020, 0x9116);
  w.begin_item();
  w.element(0x0020, 0x0037, "DS", "0\\1\\0\\-1\\0\\0");
  w.end_item();
  w.end_sequence();
  w.begin_sequence(0x0028, 0x9110);
  w.begin_item();
  w.element(0x0018, 0x0050, "DS", "+3");
  w.element(0x0028, 0x0030, "DS", " 0.5\\.25 ");
  w.end_item();
  w.end_sequence();
  w.end_item();
  w.end_sequence();
  w.begin_sequence(0x5200, 0x9230);
  for (int frame = 0; frame < 2; ++frame) {
    w.begin_item();
    w.begin_sequence(0x0020, 0x9113);
    w.begin_item();
    w.element(0x0020, 0x0032, "DS", frame == 0 ? "1\\2\\3" : "1\\2\\4.5e0");
    w.end_item();
    w.end_sequence();
    w.begin_sequence(0x0062, 0x000A);
    w.begin_item();
    w.us(0x0062, 0x000B, frame == 0 ? 9 : 7);
    w.end_item();
    w.end_sequence();
    w.end_item();
  }
  w.end_sequence();
  w.element(0x7FE0, 0x0010, "OB", std::string(12, '\x01'));
  return part10(transfer_syntax, w.bytes());
}

TEST(DicomSegHeader, ReadsTheDcmqiSegGeometry) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("dcmqi-24x38x3-seg.dcm"));
  EXPECT_EQ(h.transfer_syntax_uid, "1.2.840.10008.1.2.1");
  EXPECT_EQ(h.sop_class_uid, "1.2.840.10008.5.1.4.1.1.66.4");
  EXPECT_EQ(h.rows, 38);
  EXPECT_EQ(h.columns, 24);
  EXPECT_EQ(h.frames, 3u);
  EXPECT_EQ(h.bits_allocated, 1);
  EXPECT_EQ(h.segmentation_type, "BINARY");
  EXPECT_EQ(h.maximum_fractional_value, 0u);
  EXPECT_EQ(h.segments, 1u);
  EXPECT_EQ(h.segment_numbers, std::vector<uint16_t>({1}));
  EXPECT_EQ(h.pixel_data_offset, kDcmqiPixelDataValue);
  EXPECT_EQ(h.pixel_data_bytes, 3u * 38 * 24 / 8);
  EXPECT_EQ(h.dimension_organization_type, "");
  ASSERT_TRUE(h.orientation.has_value());
  EXPECT_EQ(*h.orientation, (std::array<double, 6>{1, 0, 0, 0, 1, 0}));
  ASSERT_TRUE(h.pixel_spacing.has_value());
  EXPECT_DOUBLE_EQ((*h.pixel_spacing)[0], 0.7);
  EXPECT_DOUBLE_EQ((*h.pixel_spacing)[1], 0.7);
  EXPECT_EQ(h.slice_thickness, 2.5);
  EXPECT_EQ(h.spacing_between_slices, 2.5);
  ASSERT_EQ(h.frame_positions.size(), 3u);
  const double z[3] = {-177.75, -175.25, -172.75};
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(h.frame_positions[frame].has_value()) << frame;
    EXPECT_DOUBLE_EQ((*h.frame_positions[frame])[0], 46.4649);
    EXPECT_DOUBLE_EQ((*h.frame_positions[frame])[1], 5.01881);
    EXPECT_DOUBLE_EQ((*h.frame_positions[frame])[2], z[frame]);
  }
  EXPECT_EQ(h.frame_segments, std::vector<uint16_t>({1, 1, 1}));
  EXPECT_FALSE(h.has_plane_position_slide);
}

TEST(DicomSegHeader, ReadsTheImplicitVrHighdicomGeometry) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("highdicom-seg_image_ct_binary.dcm"));
  EXPECT_EQ(h.transfer_syntax_uid, "1.2.840.10008.1.2");
  EXPECT_EQ(h.sop_class_uid, "1.2.840.10008.5.1.4.1.1.66.4");
  EXPECT_EQ(h.rows, 16);
  EXPECT_EQ(h.columns, 16);
  EXPECT_EQ(h.frames, 3u);
  EXPECT_EQ(h.segmentation_type, "BINARY");
  EXPECT_EQ(h.segments, 1u);
  ASSERT_TRUE(h.pixel_spacing.has_value());
  EXPECT_DOUBLE_EQ((*h.pixel_spacing)[0], 0.488281);
  EXPECT_DOUBLE_EQ((*h.pixel_spacing)[1], 0.488281);
  EXPECT_EQ(h.slice_thickness, 1.25);
  EXPECT_FALSE(h.spacing_between_slices.has_value());
  ASSERT_TRUE(h.orientation.has_value());
  EXPECT_EQ(*h.orientation, (std::array<double, 6>{1, 0, 0, 0, 1, 0}));
  ASSERT_EQ(h.frame_positions.size(), 3u);
  const double z[3] = {103.02, 104.27, 105.52};
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(h.frame_positions[frame].has_value()) << frame;
    EXPECT_DOUBLE_EQ((*h.frame_positions[frame])[0], -125.0);
    EXPECT_NEAR((*h.frame_positions[frame])[1], -128.1, 1e-5);
    EXPECT_NEAR((*h.frame_positions[frame])[2], z[frame], 1e-5);
  }
  EXPECT_EQ(h.frame_segments, std::vector<uint16_t>({1, 1, 1}));
  EXPECT_EQ(h.pixel_data_bytes, 3u * 16 * 16 / 8);
}

TEST(DicomSegHeader, ReadsWhichSegmentEachFrameHoldsWhenSegmentsOverlap) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("highdicom-seg_image_ct_binary_overlap.dcm"));
  EXPECT_EQ(h.segments, 2u);
  EXPECT_EQ(h.segment_numbers, std::vector<uint16_t>({1, 2}));
  EXPECT_EQ(h.frames, 8u);
  EXPECT_EQ(h.frame_segments, std::vector<uint16_t>({1, 1, 1, 1, 2, 2, 2, 2}));
  EXPECT_EQ(h.frame_positions.size(), 8u);
}

TEST(DicomSegHeader, ReadsAFractionalSegmentation) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("highdicom-seg_image_ct_binary_fractional.dcm"));
  EXPECT_EQ(h.segmentation_type, "FRACTIONAL");
  EXPECT_EQ(h.bits_allocated, 8);
  EXPECT_EQ(h.maximum_fractional_value, 255u);
  EXPECT_EQ(h.frames, 3u);
  EXPECT_EQ(h.pixel_data_bytes, 768u);
}

TEST(DicomSegHeader, NotesSlideMicroscopyPlanePositions) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("highdicom-seg_image_sm_control.dcm"));
  EXPECT_TRUE(h.has_plane_position_slide);
  EXPECT_EQ(h.frames, 20u);
  EXPECT_EQ(h.frame_positions.size(), 20u);
  EXPECT_EQ(h.frame_segments.size(), 20u);
}

TEST(DicomSegHeader, ReadsTheLabelmapSopClass) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const DicomSegHeader h = parse_ok(seg_file("dcmqi-sparse-labelmap-noppv.dcm"));
  EXPECT_EQ(h.sop_class_uid, "1.2.840.10008.5.1.4.1.1.66.7");
}

TEST(DicomSegHeader, EndsEveryRealFileAtItsPixelData) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  for (const auto& entry : std::filesystem::directory_iterator(testing::shared_data("dicom-seg"))) {
    if (entry.path().extension() != ".dcm") continue;
    const DicomSegHeader h = parse_ok(entry.path().string());
    EXPECT_EQ(h.pixel_data_offset + h.pixel_data_bytes, std::filesystem::file_size(entry.path()))
        << entry.path();
    EXPECT_EQ(h.frame_segments.size(), h.frames) << entry.path();
  }
}

TEST(DicomSegHeader, ReadsTheSameHeaderInEveryNativeSyntaxAndLengthForm) {
  const auto dir = testing::scratch_dir("DicomSegHeader.SyntaxAndLengthForms");
  struct Form {
    std::string_view uid;
    bool explicit_vr, big_endian;
  };
  for (const Form& form :
       {Form{"1.2.840.10008.1.2", false, false}, Form{"1.2.840.10008.1.2.1", true, false},
        Form{"1.2.840.10008.1.2.2", true, true}}) {
    for (bool undefined : {false, true}) {
      SCOPED_TRACE(std::string(form.uid) + (undefined ? " undefined lengths" : " defined lengths"));
      const auto path = dir / "seg.dcm";
      testing::write_file(path,
                          synthetic_seg(form.uid, form.explicit_vr, form.big_endian, undefined));
      const DicomSegHeader h = parse_ok(path.string());
      EXPECT_EQ(h.transfer_syntax_uid, form.uid);
      EXPECT_EQ(h.sop_class_uid, "1.2.840.10008.5.1.4.1.1.66.4");
      EXPECT_EQ(h.dimension_organization_type, "TILED_FULL");
      EXPECT_EQ(h.rows, 2);
      EXPECT_EQ(h.columns, 3);
      EXPECT_EQ(h.frames, 2u);
      EXPECT_EQ(h.bits_allocated, 8);
      EXPECT_EQ(h.segmentation_type, "FRACTIONAL");
      EXPECT_EQ(h.maximum_fractional_value, 200u);
      EXPECT_EQ(h.segment_numbers, std::vector<uint16_t>({7, 9}));
      EXPECT_EQ(h.orientation, (std::array<double, 6>{0, 1, 0, -1, 0, 0}));
      EXPECT_EQ(h.pixel_spacing, (std::array<double, 2>{0.5, 0.25}));
      EXPECT_EQ(h.slice_thickness, 3.0);
      EXPECT_FALSE(h.spacing_between_slices.has_value());
      ASSERT_EQ(h.frame_positions.size(), 2u);
      EXPECT_EQ(h.frame_positions[0], (std::array<double, 3>{1, 2, 3}));
      EXPECT_EQ(h.frame_positions[1], (std::array<double, 3>{1, 2, 4.5}));
      EXPECT_EQ(h.frame_segments, std::vector<uint16_t>({9, 7}));
      EXPECT_EQ(h.pixel_data_bytes, 12u);
      EXPECT_EQ(h.pixel_data_offset + 12, std::filesystem::file_size(path));
    }
  }
}

TEST(DicomSegHeader, ReportsAMissingFileAsNotFound) {
  auto header = parse_dicom_seg_header("/nonexistent/seg.dcm");
  EXPECT_THAT(header, testing::StatusIs(absl::StatusCode::kNotFound));
}

TEST(DicomSegHeader, RefusesAFileWithoutTheDicmMagic) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.NoMagic");
  std::string bytes = dcmqi_bytes();
  bytes.replace(128, 4, "DICX");
  expect_invalid(parse_bytes(dir, bytes), "seg.dcm: ", "not a DICOM Part-10 file");
}

TEST(DicomSegHeader, NamesRowsWhenRowsIsZero) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.RowsZero");
  std::string bytes = dcmqi_bytes();
  put_u16(bytes, kDcmqiRowsValue, 0);
  expect_invalid(parse_bytes(dir, bytes), "seg.dcm: (0028,0010) Rows: ", "is 0");
}

TEST(DicomSegHeader, RefusesBitsAllocatedASegmentationCannotHave) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Bits");
  std::string bytes = dcmqi_bytes();
  put_u16(bytes, kDcmqiBitsAllocatedValue, 12);
  expect_invalid(parse_bytes(dir, bytes), "(0028,0100) BitsAllocated", "is 12");
}

TEST(DicomSegHeader, RefusesAFrameCountThePerFrameGroupsDoNotMatch) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.FrameCount");
  std::string bytes = dcmqi_bytes();
  bytes[kDcmqiNumberOfFramesValue] = '2';
  expect_invalid(parse_bytes(dir, bytes), "(5200,9230) PerFrameFunctionalGroupsSequence",
                 "has 3 items for 2 frames");
  bytes[kDcmqiNumberOfFramesValue] = '0';
  expect_invalid(parse_bytes(dir, bytes), "(0028,0008) NumberOfFrames", "whole number");
}

TEST(DicomSegHeader, RefusesLengthsThatRunPastTheFile) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.LongLengths");
  std::string bytes = dcmqi_bytes();
  put_u32(bytes, kDcmqiSharedGroupsLength, 0xFFFFFFF0);
  expect_invalid(parse_bytes(dir, bytes), "(5200,9229) SharedFunctionalGroupsSequence",
                 "runs past the end of the file");

  // Implicit VR: every length is 4 bytes, Rows' included.
  std::string implicit = testing::read_bytes(seg_file("highdicom-seg_image_ct_binary.dcm"));
  ASSERT_EQ(implicit.substr(kCtRowsLength - 4, 4), tag_bytes(0x0028, 0x0010, ""));
  put_u32(implicit, kCtRowsLength, 0xFFFFFFF0);
  expect_invalid(parse_bytes(dir, implicit), "(0028,0010) Rows", "runs past the end of the file");

  bytes = dcmqi_bytes();
  put_u32(bytes, kDcmqiPixelDataLength, 0xFFFFFFF0);
  expect_invalid(parse_bytes(dir, bytes), "(7FE0,0010) Pixel Data",
                 "declares 4294967280 bytes, the file holds 342 after it");
}

TEST(DicomSegHeader, RefusesEncapsulatedPixelData) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Encapsulated");
  std::string bytes = dcmqi_bytes();
  put_u32(bytes, kDcmqiPixelDataLength, 0xFFFFFFFF);
  expect_invalid(parse_bytes(dir, bytes), "(7FE0,0010) Pixel Data", "encapsulated (compressed)");
}

TEST(DicomSegHeader, RefusesCompressedTransferSyntaxesByName) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Compressed");
  std::string bytes = dcmqi_bytes();
  bytes.replace(kDcmqiTransferSyntaxValue, 20, std::string("1.2.840.10008.1.2.5\0", 20));
  expect_invalid(parse_bytes(dir, bytes), "(0002,0010) TransferSyntaxUID",
                 "transfer syntax 1.2.840.10008.1.2.5: compressed or deflated DICOM SEG is not "
                 "supported");
}

TEST(DicomSegHeader, NeverEchoesATransferSyntaxThatIsNotAUid) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.FreeText");
  std::string bytes = dcmqi_bytes();
  bytes.replace(kDcmqiTransferSyntaxValue, 20, "Doe^John 1970-01-01 ");
  const absl::Status status = parse_bytes(dir, bytes);
  expect_invalid(status, "(0002,0010) TransferSyntaxUID", "not a plain UID");
  EXPECT_EQ(status.message().find("Doe"), std::string::npos) << status;
}

TEST(DicomSegHeader, RefusesDecimalStringsThatAreNotFiniteNumbers) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Decimals");
  const std::string original = dcmqi_bytes();
  for (std::string_view bad : {"nan         ", "inf         ", "4.6x6490e+01", "0x1p3       "}) {
    std::string bytes = original;
    bytes.replace(kDcmqiFirstPositionValue, 12, bad);
    expect_invalid(parse_bytes(dir, bytes), "(0020,0032) ImagePositionPatient",
                   "value 0 is not a finite number");
  }
  std::string bytes = original;
  bytes[kDcmqiFirstPositionValue + 12] = ' ';  // two values instead of three
  expect_invalid(parse_bytes(dir, bytes), "(0020,0032) ImagePositionPatient", "needs 3 values");
}

TEST(DicomSegHeader, RefusesAHeaderOverItsBudget) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Budget");
  const std::string bytes = dcmqi_bytes();
  expect_invalid(parse_bytes(dir, bytes, 2000), "", "runs past the 2000-byte limit on the header");
  EXPECT_THAT(parse_bytes(dir, bytes, kDcmqiPixelDataValue), testing::IsOk());
}

TEST(DicomSegHeader, RefusesSequencesNestedMoreThanEightDeep) {
  const auto dir = testing::scratch_dir("DicomSegHeader.Nesting");
  for (int depth : {8, 9}) {
    for (bool undefined : {false, true}) {
      DataSetWriter w(true, false, undefined);
      for (int level = 0; level < depth; ++level) {
        w.begin_sequence(0x0008, 0x1115);
        w.begin_item();
      }
      for (int level = 0; level < depth; ++level) {
        w.end_item();
        w.end_sequence();
      }
      w.element(0x7FE0, 0x0010, "OB", "");
      const absl::Status status = parse_bytes(dir, part10("1.2.840.10008.1.2.1", w.bytes()));
      if (depth == 8) {
        EXPECT_THAT(status, testing::IsOk());
      } else {
        expect_invalid(status, "(0008,1115)", "nests sequences more than 8 deep");
      }
    }
  }
}

TEST(DicomSegHeader, AppliesASharedPositionAndSegmentToEveryFrame) {
  const auto dir = testing::scratch_dir("DicomSegHeader.Shared");
  DataSetWriter w(false, false, false);
  w.element(0x0028, 0x0008, "IS", "3");
  w.begin_sequence(0x5200, 0x9229);
  w.begin_item();
  w.begin_sequence(0x0020, 0x9113);
  w.begin_item();
  w.element(0x0020, 0x0032, "DS", "1\\2\\3");
  w.end_item();
  w.end_sequence();
  w.begin_sequence(0x0062, 0x000A);
  w.begin_item();
  w.us(0x0062, 0x000B, 4);
  w.end_item();
  w.end_sequence();
  w.end_item();
  w.end_sequence();
  w.element(0x7FE0, 0x0010, "OW", "");
  const auto path = dir / "seg.dcm";
  testing::write_file(path, part10("1.2.840.10008.1.2", w.bytes()));
  const DicomSegHeader h = parse_ok(path.string());
  ASSERT_EQ(h.frame_positions.size(), 3u);
  for (const auto& position : h.frame_positions) {
    EXPECT_EQ(position, (std::array<double, 3>{1, 2, 3}));
  }
  EXPECT_EQ(h.frame_segments, std::vector<uint16_t>({4, 4, 4}));
}

TEST(DicomSegHeader, RefusesMisplacedDelimitersAndUndefinedLengths) {
  const auto dir = testing::scratch_dir("DicomSegHeader.Delimiters");
  {
    // A sequence of undefined length that never ends: Pixel Data sits where an item belongs.
    DataSetWriter w(true, false, true);
    w.begin_sequence(0x0062, 0x0002);
    w.element(0x7FE0, 0x0010, "OB", "");
    expect_invalid(parse_bytes(dir, part10("1.2.840.10008.1.2.1", w.bytes())),
                   "(0062,0002) SegmentSequence", "holds (7FE0,0010) Pixel Data");
  }
  {
    DataSetWriter w(true, false, true);
    w.begin_item();
    w.end_item();
    expect_invalid(parse_bytes(dir, part10("1.2.840.10008.1.2.1", w.bytes())), "(FFFE,E000)",
                   "is out of place");
  }
  {
    // Explicit VR UN of undefined length is not a sequence here.
    std::string data_set("\x09\x00\x10\x00UN\0\0\xFF\xFF\xFF\xFF", 12);
    expect_invalid(parse_bytes(dir, part10("1.2.840.10008.1.2.1", data_set)), "(0009,0010)",
                   "undefined length but is not a sequence");
  }
}

TEST(DicomSegHeader, RefusesAnExplicitVrThatContradictsTheDictionary) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.WrongVr");
  std::string bytes = dcmqi_bytes();
  bytes.replace(kDcmqiRowsValue - 4, 2, "SS");
  expect_invalid(parse_bytes(dir, bytes), "(0028,0010) Rows", "has VR SS; PS3.6 gives US");
  bytes.replace(kDcmqiRowsValue - 4, 2, "Q?");
  expect_invalid(parse_bytes(dir, bytes), "(0028,0010) Rows", "is not one PS3.5 defines");
}

TEST(DicomSegHeader, RefusesMoreFramesOrSegmentsThanItsLimits) {
  const auto dir = testing::scratch_dir("DicomSegHeader.Limits");
  {
    DataSetWriter w(true, false, false);
    w.element(0x0028, 0x0008, "IS", "1000001");
    w.element(0x7FE0, 0x0010, "OB", "");
    expect_invalid(parse_bytes(dir, part10("1.2.840.10008.1.2.1", w.bytes())),
                   "(0028,0008) NumberOfFrames", "is not a whole number from 1 to 1000000");
  }
  for (int segments : {65535, 65536}) {
    DataSetWriter w(true, false, false);
    w.begin_sequence(0x0062, 0x0002);
    for (int i = 0; i < segments; ++i) {
      w.begin_item();
      w.end_item();
    }
    w.end_sequence();
    w.element(0x7FE0, 0x0010, "OB", "");
    const absl::Status status = parse_bytes(dir, part10("1.2.840.10008.1.2.1", w.bytes()));
    if (segments == 65535) {
      EXPECT_THAT(status, testing::IsOk());
    } else {
      expect_invalid(status, "(0062,0002) SegmentSequence", "holds more than 65535 segments");
    }
  }
}

TEST(DicomSegHeader, NamesWhatATruncationCuts) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.Truncations");
  const std::string bytes = dcmqi_bytes();
  const std::pair<size_t, std::string_view> cuts[] = {
      {100, "not a DICOM Part-10 file"},
      {134, "file meta information"},
      {1900, "data set"},
      {2300, "(5200,9229) SharedFunctionalGroupsSequence"},
      {kDcmqiPixelDataValue, "(7FE0,0010) Pixel Data: declares 342 bytes, the file holds 0"},
      {kDcmqiPixelDataValue + 100, "the file holds 100 after it"},
  };
  for (const auto& [size, named] : cuts) {
    expect_invalid(parse_bytes(dir, bytes.substr(0, size)), "seg.dcm: ", named);
  }
}

TEST(DicomSegHeader, FailsCleanlyWhereverTheFileIsCut) {
  LABELMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = testing::scratch_dir("DicomSegHeader.EveryCut");
  const auto path = dir / "seg.dcm";
  for (const char* name : {"dcmqi-24x38x3-seg.dcm", "highdicom-seg_image_ct_binary.dcm"}) {
    const std::string bytes = testing::read_bytes(seg_file(name));
    testing::write_file(path, bytes);
    EXPECT_THAT(parse_dicom_seg_header(path.string()), testing::IsOk()) << name;
    // Shortening the one file in place visits every length from size - 1 to 0.
    for (size_t size = bytes.size(); size-- > 0;) {
      std::filesystem::resize_file(path, size);
      const absl::Status status = parse_dicom_seg_header(path.string()).status();
      ASSERT_EQ(status.code(), absl::StatusCode::kInvalidArgument)
          << name << " cut at " << size << ": " << status;
    }
  }
}

}  // namespace
}  // namespace labelmesh
