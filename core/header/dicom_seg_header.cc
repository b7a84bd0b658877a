// SPDX-License-Identifier: AGPL-3.0-or-later
// DICOM Part-10 header walk. Layout (PS3.10 7.1): a 128-byte preamble,
// "DICM", the File Meta group 0002 in explicit VR little endian, then the
// data set in the transfer syntax named by (0002,0010). Data elements follow
// PS3.5 7.1.2 (explicit VR: a 2-byte length, or 2 reserved bytes and a 4-byte
// length for the VRs of table 7.1-1) and 7.1.3 (implicit VR: a 4-byte length,
// the VR known from the data dictionary). Sequences and items follow PS3.5
// 7.5: defined lengths, or undefined ones (0xFFFFFFFF) closed by the item
// (FFFE,E00D) and sequence (FFFE,E0DD) delimiters.
#include "core/header/dicom_seg_header.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"

namespace labelmesh::volume::internal {
namespace {

constexpr int kMaxDepth = 8;
constexpr uint32_t kMaxFrames = 1'000'000;
constexpr uint32_t kMaxSegments = 65'535;
constexpr uint32_t kUndefinedLength = 0xFFFFFFFF;
constexpr uint64_t kNoEnd = std::numeric_limits<uint64_t>::max();
constexpr size_t kWindowBytes = size_t{64} << 10;
// The values we read are UIDs (64 bytes), code strings and at most six
// decimal strings of 16 bytes; anything longer is no valid value of theirs.
constexpr uint32_t kMaxValueBytes = 1024;

constexpr uint32_t tag(uint32_t group, uint32_t element) { return group << 16 | element; }

constexpr uint32_t kItem = tag(0xFFFE, 0xE000);
constexpr uint32_t kItemEnd = tag(0xFFFE, 0xE00D);
constexpr uint32_t kSequenceEnd = tag(0xFFFE, 0xE0DD);
constexpr uint32_t kTransferSyntax = tag(0x0002, 0x0010);
constexpr uint32_t kSopClass = tag(0x0008, 0x0016);
constexpr uint32_t kSliceThickness = tag(0x0018, 0x0050);
constexpr uint32_t kSpacingBetweenSlices = tag(0x0018, 0x0088);
constexpr uint32_t kImagePosition = tag(0x0020, 0x0032);
constexpr uint32_t kImageOrientation = tag(0x0020, 0x0037);
constexpr uint32_t kPlanePositionSequence = tag(0x0020, 0x9113);
constexpr uint32_t kPlaneOrientationSequence = tag(0x0020, 0x9116);
constexpr uint32_t kDimensionOrganizationType = tag(0x0020, 0x9311);
constexpr uint32_t kNumberOfFrames = tag(0x0028, 0x0008);
constexpr uint32_t kRows = tag(0x0028, 0x0010);
constexpr uint32_t kColumns = tag(0x0028, 0x0011);
constexpr uint32_t kPixelSpacing = tag(0x0028, 0x0030);
constexpr uint32_t kBitsAllocated = tag(0x0028, 0x0100);
constexpr uint32_t kPixelMeasuresSequence = tag(0x0028, 0x9110);
constexpr uint32_t kPlanePositionSlideSequence = tag(0x0048, 0x021A);
constexpr uint32_t kSegmentationType = tag(0x0062, 0x0001);
constexpr uint32_t kSegmentSequence = tag(0x0062, 0x0002);
constexpr uint32_t kSegmentNumber = tag(0x0062, 0x0004);
constexpr uint32_t kSegmentIdentificationSequence = tag(0x0062, 0x000A);
constexpr uint32_t kReferencedSegmentNumber = tag(0x0062, 0x000B);
constexpr uint32_t kMaximumFractionalValue = tag(0x0062, 0x000E);
constexpr uint32_t kSharedGroups = tag(0x5200, 0x9229);
constexpr uint32_t kPerFrameGroups = tag(0x5200, 0x9230);
constexpr uint32_t kPixelData = tag(0x7FE0, 0x0010);

// The data dictionary (PS3.6) entries of the tags we read or descend into:
// implicit VR needs their VR, and explicit VR must agree with it.
struct KnownTag {
  uint32_t tag;
  std::string_view vr;
  std::string_view name;
};
constexpr KnownTag kKnownTags[] = {
    {kTransferSyntax, "UI", "TransferSyntaxUID"},
    {kSopClass, "UI", "SOPClassUID"},
    {kSliceThickness, "DS", "SliceThickness"},
    {kSpacingBetweenSlices, "DS", "SpacingBetweenSlices"},
    {kImagePosition, "DS", "ImagePositionPatient"},
    {kImageOrientation, "DS", "ImageOrientationPatient"},
    {kPlanePositionSequence, "SQ", "PlanePositionSequence"},
    {kPlaneOrientationSequence, "SQ", "PlaneOrientationSequence"},
    {kDimensionOrganizationType, "CS", "DimensionOrganizationType"},
    {kNumberOfFrames, "IS", "NumberOfFrames"},
    {kRows, "US", "Rows"},
    {kColumns, "US", "Columns"},
    {kPixelSpacing, "DS", "PixelSpacing"},
    {kBitsAllocated, "US", "BitsAllocated"},
    {kPixelMeasuresSequence, "SQ", "PixelMeasuresSequence"},
    {kPlanePositionSlideSequence, "SQ", "PlanePositionSlideSequence"},
    {kSegmentationType, "CS", "SegmentationType"},
    {kSegmentSequence, "SQ", "SegmentSequence"},
    {kSegmentNumber, "US", "SegmentNumber"},
    {kSegmentIdentificationSequence, "SQ", "SegmentIdentificationSequence"},
    {kReferencedSegmentNumber, "US", "ReferencedSegmentNumber"},
    {kMaximumFractionalValue, "US", "MaximumFractionalValue"},
    {kSharedGroups, "SQ", "SharedFunctionalGroupsSequence"},
    {kPerFrameGroups, "SQ", "PerFrameFunctionalGroupsSequence"},
    {kPixelData, "", "Pixel Data"}};

const KnownTag* known_tag(uint32_t t) {
  for (const auto& k : kKnownTags) {
    if (k.tag == t) return &k;
  }
  return nullptr;
}

// "(0028,0010) Rows", or just "(gggg,eeee)" for a tag we do not know.
std::string tag_name(uint32_t t) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "(%04X,%04X)", t >> 16, t & 0xFFFF);
  const KnownTag* k = known_tag(t);
  return k ? cat(hex, " ", k->name) : std::string(hex);
}

// PS3.5 table 7.1-1 and 7.1-2, two letters each: VRs with a 2-byte length,
// and those with 2 reserved bytes and a 4-byte length.
constexpr std::string_view kShortVrs = "AEASATCSDADSDTFLFDISLOLTPNSHSLSSSTTMUIULUS";
constexpr std::string_view kLongVrs = "OBODOFOLOVOWSQSVUCUNURUTUV";

// The VR as it appears in `list`, or empty when it is not there.
std::string_view find_vr(std::string_view list, std::string_view vr) {
  for (size_t i = 0; i + 2 <= list.size(); i += 2) {
    if (list.substr(i, 2) == vr) return list.substr(i, 2);
  }
  return {};
}

struct Element {
  uint32_t tag = 0;
  std::string_view vr;  // explicit VR only; points into kShortVrs/kLongVrs
  uint32_t length = 0;
  uint64_t value_offset = 0;
};

// Where an element sits, which decides what its value means.
enum class Scope {
  kDataSet,
  kSegment,
  kShared,
  kFrame,
  kOrientation,
  kMeasures,
  kPosition,
  kSegmentId,
  kOther
};

Scope item_scope(Scope parent, uint32_t sequence) {
  if (parent == Scope::kDataSet) {
    if (sequence == kSegmentSequence) return Scope::kSegment;
    if (sequence == kSharedGroups) return Scope::kShared;
    if (sequence == kPerFrameGroups) return Scope::kFrame;
  }
  if (parent == Scope::kShared || parent == Scope::kFrame) {
    if (sequence == kPlaneOrientationSequence) return Scope::kOrientation;
    if (sequence == kPixelMeasuresSequence) return Scope::kMeasures;
    if (sequence == kPlanePositionSequence) return Scope::kPosition;
    if (sequence == kSegmentIdentificationSequence) return Scope::kSegmentId;
  }
  return Scope::kOther;
}

// What one functional-groups item (the shared one, or one frame's) holds.
struct FrameGroups {
  std::optional<std::array<double, 6>> orientation;
  std::optional<std::array<double, 2>> pixel_spacing;
  std::optional<std::array<double, 1>> slice_thickness, spacing_between_slices;
  std::optional<std::array<double, 3>> position;
  uint16_t segment = 0;
};

// Padding in UIDs, code and number strings is insignificant (PS3.5 6.2).
std::string_view strip(std::string_view text) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\0')) text.remove_suffix(1);
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  return text;
}

std::optional<double> single(const std::optional<std::array<double, 1>>& value) {
  return value ? std::optional<double>((*value)[0]) : std::nullopt;
}

class Walker {
 public:
  Walker(const std::string& path, uint64_t file_size, uint64_t max_header)
      : path_(path), in_(path, std::ios::binary), file_size_(file_size), max_header_(max_header) {}

  absl::StatusOr<DicomSegHeader> run();

 private:
  // [offset, offset + count) lies inside the file and the header budget.
  absl::Status span(std::string_view field, std::string_view what, uint64_t offset,
                    uint64_t count) const {
    const bool in_file = offset <= file_size_ && count <= file_size_ - offset;
    if (in_file && offset <= max_header_ && count <= max_header_ - offset) return absl::OkStatus();
    return field_error(path_, field,
                       cat(what, " of ", count, " bytes at byte ", offset, " runs past ",
                           in_file ? cat("the ", max_header_, "-byte limit on the header")
                                   : cat("the end of the file (", file_size_, " bytes)")));
  }

  // Copies [offset, offset + count) out through a bounded window that moves
  // forward with the walk, so no buffer is ever sized by the file. The caller
  // has checked the span with span() and count <= kMaxValueBytes.
  absl::Status read(uint64_t offset, size_t count, char* out) {
    if (offset < window_start_ || offset + count > window_start_ + window_.size()) {
      window_.resize(static_cast<size_t>(std::min<uint64_t>(kWindowBytes, file_size_ - offset)));
      in_.clear();
      in_.seekg(static_cast<std::streamoff>(offset));
      in_.read(window_.data(), static_cast<std::streamsize>(window_.size()));
      window_.resize(static_cast<size_t>(std::max<std::streamsize>(0, in_.gcount())));
      window_start_ = offset;
      if (count > window_.size()) {
        return field_error(path_, "file", cat("could not be read at byte ", offset));
      }
    }
    std::memcpy(out, window_.data() + (offset - window_start_), count);
    return absl::OkStatus();
  }

  uint32_t number(const char* bytes, int size) const {
    uint32_t value = 0;
    for (int i = 0; i < size; ++i) {
      const auto byte = static_cast<unsigned char>(bytes[syntax_.big_endian ? size - 1 - i : i]);
      value |= uint32_t{byte} << (8 * i);
    }
    return value;
  }

  absl::StatusOr<Element> element_at(uint64_t pos, int depth);
  absl::StatusOr<uint64_t> walk_elements(uint64_t pos, uint64_t end, bool until_item_end, int depth,
                                         Scope scope, FrameGroups* groups);
  absl::StatusOr<uint64_t> walk_sequence(const Element& sequence, uint64_t outer_end, int depth,
                                         Scope parent, FrameGroups* groups);
  absl::Status pixel_data(const Element& e);
  absl::Status use_value(const Element& e, Scope scope, FrameGroups* groups);

  absl::StatusOr<std::string> text(const Element& e) {
    if (e.length > kMaxValueBytes) {
      return field_error(path_, tag_name(e.tag),
                         cat("is ", e.length, " bytes; at most ", kMaxValueBytes, " are accepted"));
    }
    std::string bytes(e.length, '\0');
    LABELMESH_RETURN_IF_ERROR(read(e.value_offset, e.length, bytes.data()));
    return std::string(strip(bytes));
  }

  absl::Status store_text(const Element& e, std::string& out) {
    auto value = text(e);
    if (!value.ok()) return value.status();
    out = *std::move(value);
    return absl::OkStatus();
  }

  // A US value (VM 1) into `out`, refused when `allowed` says no.
  template <typename T>
  absl::Status store_us(const Element& e, T& out, bool (*allowed)(uint16_t) = nullptr,
                        std::string_view need = {}) {
    char raw[2];
    if (e.length != 2) {
      return field_error(path_, tag_name(e.tag), cat("is ", e.length, " bytes; a US value is 2"));
    }
    LABELMESH_RETURN_IF_ERROR(read(e.value_offset, 2, raw));
    const auto value = static_cast<uint16_t>(number(raw, 2));
    if (allowed && !allowed(value)) {
      return field_error(path_, tag_name(e.tag), cat("is ", value, need));
    }
    out = value;
    return absl::OkStatus();
  }

  // A decimal string (PS3.5 table 6.2-1, DS) of exactly N values; an empty
  // value (type 2) leaves `out` unset.
  template <size_t N>
  absl::Status store_decimals(const Element& e, std::optional<std::array<double, N>>& out) {
    auto value = text(e);
    if (!value.ok()) return value.status();
    if (value->empty()) return absl::OkStatus();
    const std::vector<std::string_view> parts = split_any(*value, "\\");
    const size_t values = static_cast<size_t>(std::count(value->begin(), value->end(), '\\')) + 1;
    if (parts.size() != N || values != N) {
      return field_error(path_, tag_name(e.tag), cat("needs ", N, " values, found ", values));
    }
    std::array<double, N> numbers{};
    for (size_t i = 0; i < N; ++i) {
      std::string_view token = strip(parts[i]);
      if (!token.empty() && token.front() == '+') token.remove_prefix(1);
      const char* stop = token.data() + token.size();
      const auto result = std::from_chars(token.data(), stop, numbers[i]);
      if (token.empty() || result.ec != std::errc() || result.ptr != stop ||
          !std::isfinite(numbers[i])) {
        return field_error(path_, tag_name(e.tag), cat("value ", i, " is not a finite number"));
      }
    }
    out = numbers;
    return absl::OkStatus();
  }

  const std::string& path_;
  std::ifstream in_;
  uint64_t file_size_;
  uint64_t max_header_;
  std::string window_;
  uint64_t window_start_ = 0;
  struct {
    bool explicit_vr = true;
    bool big_endian = false;
  } syntax_;
  DicomSegHeader out_;
  bool per_frame_seen_ = false;
  FrameGroups shared_;
  FrameGroups first_frame_;
};

absl::StatusOr<Element> Walker::element_at(uint64_t pos, int depth) {
  if (pos >= file_size_) {
    if (depth == 0) {
      return field_error(path_, tag_name(kPixelData),
                         cat("is missing: the file ends at byte ", pos));
    }
    return field_error(path_, "data set", cat("the file ends at byte ", pos, " inside a sequence"));
  }
  LABELMESH_RETURN_IF_ERROR(span("data set", "an element header", pos, 8));
  char raw[12];
  LABELMESH_RETURN_IF_ERROR(read(pos, 8, raw));
  Element e;
  e.tag = number(raw, 2) << 16 | number(raw + 2, 2);
  e.value_offset = pos + 8;
  if (e.tag >> 16 == 0xFFFE || !syntax_.explicit_vr) {  // items and delimiters carry no VR
    e.length = number(raw + 4, 4);
    return e;
  }
  const std::string_view vr(raw + 4, 2);
  if (e.vr = find_vr(kShortVrs, vr); !e.vr.empty()) {
    e.length = number(raw + 6, 2);
    return e;
  }
  if (e.vr = find_vr(kLongVrs, vr); e.vr.empty()) {
    return field_error(path_, tag_name(e.tag),
                       cat("the VR at byte ", pos + 4, " is not one PS3.5 defines"));
  }
  LABELMESH_RETURN_IF_ERROR(span(tag_name(e.tag), "an element header", pos, 12));
  LABELMESH_RETURN_IF_ERROR(read(pos + 8, 4, raw + 8));
  e.length = number(raw + 8, 4);
  e.value_offset = pos + 12;
  return e;
}

// The elements from `pos` up to `end`, or up to the item delimiter when
// `until_item_end`; returns the offset just past them. At depth 0 only
// Pixel Data ends the walk.
absl::StatusOr<uint64_t> Walker::walk_elements(uint64_t pos, uint64_t end, bool until_item_end,
                                               int depth, Scope scope, FrameGroups* groups) {
  while (until_item_end || pos < end) {
    LABELMESH_ASSIGN_OR_RETURN(auto e, element_at(pos, depth));
    const KnownTag* known = known_tag(e.tag);
    if (e.value_offset > end) {
      return field_error(path_, tag_name(e.tag),
                         cat("runs past the end of its item at byte ", end));
    }
    if (e.tag == kItemEnd && until_item_end) return e.value_offset;
    if (e.tag >> 16 == 0xFFFE) {
      return field_error(path_, tag_name(e.tag), cat("is out of place at byte ", pos));
    }
    if (syntax_.explicit_vr && known && !known->vr.empty() && e.vr != known->vr) {
      return field_error(path_, tag_name(e.tag), cat("has VR ", e.vr, "; PS3.6 gives ", known->vr));
    }
    if (depth == 0 && e.tag == kPixelData) {
      LABELMESH_RETURN_IF_ERROR(pixel_data(e));
      return end;
    }
    // Implicit VR: our sequences are known, and an undefined length outside
    // Pixel Data can only be a sequence (PS3.5 7.5.1).
    const bool sequence =
        syntax_.explicit_vr
            ? e.vr == "SQ"
            : (known && known->vr == "SQ") || (e.length == kUndefinedLength && e.tag != kPixelData);
    if (sequence) {
      if (e.tag == kPlanePositionSlideSequence) out_.has_plane_position_slide = true;
      LABELMESH_ASSIGN_OR_RETURN(auto next, walk_sequence(e, end, depth + 1, scope, groups));
      pos = next;
      continue;
    }
    if (e.length == kUndefinedLength) {
      return field_error(path_, tag_name(e.tag), "has an undefined length but is not a sequence");
    }
    if (e.value_offset + e.length > std::min({end, max_header_, file_size_})) {
      LABELMESH_RETURN_IF_ERROR(span(tag_name(e.tag), "a value", e.value_offset, e.length));
      return field_error(path_, tag_name(e.tag),
                         cat("runs past the end of its item at byte ", end));
    }
    LABELMESH_RETURN_IF_ERROR(use_value(e, scope, groups));
    pos = e.value_offset + e.length;
  }
  return pos;
}

absl::StatusOr<uint64_t> Walker::walk_sequence(const Element& sequence, uint64_t outer_end,
                                               int depth, Scope parent, FrameGroups* groups) {
  const std::string field = tag_name(sequence.tag);
  if (depth > kMaxDepth) {
    return field_error(path_, field, cat("nests sequences more than ", kMaxDepth, " deep"));
  }
  const bool undefined = sequence.length == kUndefinedLength;
  uint64_t end = outer_end;
  if (!undefined) {
    if (auto s = span(field, "a sequence", sequence.value_offset, sequence.length); !s.ok()) {
      return s;
    }
    if (sequence.length > outer_end - sequence.value_offset) {
      return field_error(path_, field, cat("runs past the end of its item at byte ", outer_end));
    }
    end = sequence.value_offset + sequence.length;
  }
  const Scope scope = item_scope(parent, sequence.tag);
  per_frame_seen_ = per_frame_seen_ || scope == Scope::kFrame;
  uint64_t pos = sequence.value_offset;
  while (undefined || pos < end) {
    auto item = element_at(pos, depth);
    if (!item.ok()) return item.status();
    if (item->tag == kSequenceEnd && undefined && item->value_offset <= end) {
      return item->value_offset;
    }
    if (item->tag != kItem) {
      return field_error(
          path_, field,
          cat("holds ", tag_name(item->tag), " at byte ", pos, " where an item belongs"));
    }
    FrameGroups frame;
    FrameGroups* item_groups = scope == Scope::kShared  ? &shared_
                               : scope == Scope::kFrame ? &frame
                                                        : groups;
    if (scope == Scope::kSegment) {
      if (out_.segment_numbers.size() >= kMaxSegments) {
        return field_error(path_, field, cat("holds more than ", kMaxSegments, " segments"));
      }
      out_.segment_numbers.push_back(0);
    }
    if (scope == Scope::kFrame && out_.frame_positions.size() >= kMaxFrames) {
      return field_error(path_, field, cat("holds more than ", kMaxFrames, " frames"));
    }
    absl::StatusOr<uint64_t> next;
    if (item->length == kUndefinedLength) {
      next = walk_elements(item->value_offset, end, true, depth, scope, item_groups);
    } else if (auto s = span(field, "an item", item->value_offset, item->length); !s.ok()) {
      return s;
    } else if (item->value_offset > end || item->length > end - item->value_offset) {
      return field_error(path_, field, cat("has an item that runs past its end at byte ", end));
    } else {
      next = walk_elements(item->value_offset, item->value_offset + item->length, false, depth,
                           scope, item_groups);
    }
    if (!next.ok()) return next.status();
    pos = *next;
    if (scope == Scope::kFrame) {
      if (out_.frame_positions.empty()) first_frame_ = frame;
      out_.frame_positions.push_back(frame.position);
      out_.frame_segments.push_back(frame.segment);
    }
  }
  return pos;
}

absl::Status Walker::pixel_data(const Element& e) {
  const std::string field = tag_name(kPixelData);
  if (e.length == kUndefinedLength) {
    return field_error(path_, field, "is encapsulated (compressed)");
  }
  if (syntax_.explicit_vr && e.vr != "OB" && e.vr != "OW") {
    return field_error(path_, field, cat("has VR ", e.vr, "; native pixel data is OB or OW"));
  }
  if (e.length > file_size_ - e.value_offset) {
    return field_error(path_, field,
                       cat("declares ", e.length, " bytes, the file holds ",
                           file_size_ - e.value_offset, " after it"));
  }
  out_.pixel_data_offset = e.value_offset;
  out_.pixel_data_bytes = e.length;
  return absl::OkStatus();
}

bool positive(uint16_t value) { return value > 0; }
bool segmentation_bits(uint16_t value) { return value == 1 || value == 8 || value == 16; }

absl::Status Walker::use_value(const Element& e, Scope scope, FrameGroups* groups) {
  switch (scope) {
    case Scope::kDataSet:
      if (e.tag == kSopClass) return store_text(e, out_.sop_class_uid);
      if (e.tag == kSegmentationType) return store_text(e, out_.segmentation_type);
      if (e.tag == kDimensionOrganizationType) {
        return store_text(e, out_.dimension_organization_type);
      }
      if (e.tag == kRows) return store_us(e, out_.rows, positive);
      if (e.tag == kColumns) return store_us(e, out_.columns, positive);
      if (e.tag == kMaximumFractionalValue) return store_us(e, out_.maximum_fractional_value);
      if (e.tag == kBitsAllocated) {
        return store_us(e, out_.bits_allocated, segmentation_bits,
                        "; a segmentation has 1, 8 or 16");
      }
      if (e.tag == kNumberOfFrames) {
        LABELMESH_ASSIGN_OR_RETURN(auto value, text(e));
        std::string_view digits = value;
        if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
        uint32_t frames = 0;
        const char* stop = digits.data() + digits.size();
        const auto result = std::from_chars(digits.data(), stop, frames);
        if (digits.empty() || result.ec != std::errc() || result.ptr != stop || frames < 1 ||
            frames > kMaxFrames) {
          return field_error(path_, tag_name(e.tag),
                             cat("is not a whole number from 1 to ", kMaxFrames));
        }
        out_.frames = frames;
      }
      return absl::OkStatus();
    case Scope::kSegment:
      return e.tag == kSegmentNumber ? store_us(e, out_.segment_numbers.back()) : absl::OkStatus();
    case Scope::kSegmentId:
      return e.tag == kReferencedSegmentNumber ? store_us(e, groups->segment) : absl::OkStatus();
    case Scope::kOrientation:
      return e.tag == kImageOrientation ? store_decimals(e, groups->orientation) : absl::OkStatus();
    case Scope::kPosition:
      return e.tag == kImagePosition ? store_decimals(e, groups->position) : absl::OkStatus();
    case Scope::kMeasures:
      if (e.tag == kPixelSpacing) return store_decimals(e, groups->pixel_spacing);
      if (e.tag == kSliceThickness) return store_decimals(e, groups->slice_thickness);
      if (e.tag == kSpacingBetweenSlices) return store_decimals(e, groups->spacing_between_slices);
      return absl::OkStatus();
    default:
      return absl::OkStatus();
  }
}

absl::StatusOr<DicomSegHeader> Walker::run() {
  if (!in_) return absl::NotFoundError(cat(path_, ": cannot open the file"));
  char magic[4] = {};
  if (file_size_ < 132 || !read(128, 4, magic).ok() || std::memcmp(magic, "DICM", 4) != 0) {
    return field_error(path_, "preamble", "not a DICOM Part-10 file (no \"DICM\" at byte 128)");
  }
  // File Meta: explicit VR little endian whatever the data set uses (PS3.10 7.1).
  uint64_t pos = 132;
  bool have_syntax = false;
  while (true) {
    LABELMESH_RETURN_IF_ERROR(span("file meta information", "an element header", pos, 8));
    char group[2];
    LABELMESH_RETURN_IF_ERROR(read(pos, 2, group));
    if (number(group, 2) != 0x0002) break;
    auto e = element_at(pos, /*depth=*/1);  // never at the end of the file: checked above
    if (!e.ok()) return e.status();
    LABELMESH_RETURN_IF_ERROR(span(tag_name(e->tag), "a value", e->value_offset, e->length));
    if (e->tag == kTransferSyntax) {
      LABELMESH_RETURN_IF_ERROR(store_text(*e, out_.transfer_syntax_uid));
      have_syntax = true;
    }
    pos = e->value_offset + e->length;
  }
  const std::string& uid = out_.transfer_syntax_uid;
  if (!have_syntax) return field_error(path_, tag_name(kTransferSyntax), "is missing");
  if (uid == "1.2.840.10008.1.2") {
    syntax_ = {.explicit_vr = false, .big_endian = false};
  } else if (uid == "1.2.840.10008.1.2.2") {
    syntax_ = {.explicit_vr = true, .big_endian = true};
  } else if (uid != "1.2.840.10008.1.2.1") {
    return field_error(path_, tag_name(kTransferSyntax),
                       cat("transfer syntax ", is_plain_uid(uid) ? uid : "(not a plain UID)",
                           ": compressed or deflated DICOM SEG is not supported"));
  }

  LABELMESH_RETURN_IF_ERROR(walk_elements(pos, kNoEnd, false, 0, Scope::kDataSet, nullptr));

  if (per_frame_seen_ && out_.frame_positions.size() != out_.frames) {
    return field_error(path_, tag_name(kPerFrameGroups),
                       cat("has ", out_.frame_positions.size(), " items for ", out_.frames,
                           " frames (0028,0008)"));
  }
  out_.segments = static_cast<uint32_t>(out_.segment_numbers.size());
  const FrameGroups& f = first_frame_;
  out_.orientation = shared_.orientation ? shared_.orientation : f.orientation;
  out_.pixel_spacing = shared_.pixel_spacing ? shared_.pixel_spacing : f.pixel_spacing;
  out_.slice_thickness =
      single(shared_.slice_thickness ? shared_.slice_thickness : f.slice_thickness);
  out_.spacing_between_slices = single(
      shared_.spacing_between_slices ? shared_.spacing_between_slices : f.spacing_between_slices);
  // Shared values stand for every frame (PS3.3 C.7.6.16); frames is at most
  // kMaxFrames, so this allocation is bounded.
  if (per_frame_seen_ || shared_.position || shared_.segment != 0) {
    out_.frame_positions.resize(out_.frames);
    out_.frame_segments.resize(out_.frames, 0);
    for (uint32_t i = 0; i < out_.frames; ++i) {
      if (!out_.frame_positions[i]) out_.frame_positions[i] = shared_.position;
      if (out_.frame_segments[i] == 0) out_.frame_segments[i] = shared_.segment;
    }
  }
  return std::move(out_);
}

}  // namespace

bool is_plain_uid(std::string_view uid) {
  return !uid.empty() && uid.size() <= 64 && std::all_of(uid.begin(), uid.end(), [](char c) {
    return c == '.' || (c >= '0' && c <= '9');
  });
}

absl::StatusOr<DicomSegHeader> parse_dicom_seg_header(const std::string& path,
                                                      uint64_t max_header_bytes) {
  LABELMESH_ASSIGN_OR_RETURN(auto size, file_size(path));
  return Walker(path, size, max_header_bytes).run();
}

}  // namespace labelmesh::volume::internal
