// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/read_dicom_seg.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmiod/cielabutil.h>
#include <dcmtk/dcmseg/segdoc.h>
#include <dcmtk/dcmseg/segment.h>
#include <dcmtk/oflog/oflog.h>
#include <vtkPointData.h>
#include <vtkUnsignedShortArray.h>

#include "absl/strings/str_cat.h"
#include "core/header/dicom_seg_grid.h"
#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/utf8.h"
#include "core/volume/segment_layers.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

// DCMTK logs to the console by default; errors reach the caller as statuses.
void silence_dcmtk() {
  static const bool silenced = [] {
    OFLog::configure(OFLogger::OFF_LOG_LEVEL);
    return true;
  }();
  (void)silenced;
}

CodedConcept concept_of(CodeSequenceMacro& code) {
  CodedConcept coded;
  OFString text;
  if (code.getCodingSchemeDesignator(text).good()) coded.scheme = valid_utf8(text.c_str());
  if (code.getCodeValue(text).good()) coded.value = valid_utf8(text.c_str());
  if (code.getCodeMeaning(text).good()) coded.meaning = valid_utf8(text.c_str());
  return coded;
}

LabelDescription describe(int32_t label, DcmSegment& segment) {
  LabelDescription description;
  description.label = label;
  OFString name;
  // In the file's own character set; Latin-1 names lose their accents.
  if (segment.getSegmentLabel(name).good()) description.name = valid_utf8(name.c_str());
  Uint16 l = 0, a = 0, b = 0;
  if (segment.getRecommendedDisplayCIELabValue(l, a, b).good()) {
    double rgb[3];
    IODCIELabUtil::dicomLab2RGB(rgb[0], rgb[1], rgb[2], l, a, b);
    std::array<uint8_t, 3> colour{};
    for (int c = 0; c < 3; ++c)
      colour[c] = static_cast<uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255));
    description.colour = colour;
  }
  description.category = concept_of(segment.getSegmentedPropertyCategoryCode());
  description.type = concept_of(segment.getSegmentedPropertyTypeCode());
  return description;
}

// The Pixel Data bytes as stored, in file order (DCMTK swaps OW words of a
// big-endian file to this machine's order, which for packed bits restores
// the little-endian bit stream the standard defines).
absl::StatusOr<std::pair<const uint8_t*, size_t>> pixel_bytes(const std::string& path,
                                                              DcmDataset& dataset) {
  DcmElement* element = nullptr;
  if (dataset.findAndGetElement(DCM_PixelData, element).bad() || element == nullptr) {
    return field_error(path, "(7FE0,0010) Pixel Data", "is missing");
  }
  Uint8* bytes = nullptr;
  if (element->getUint8Array(bytes).bad() || bytes == nullptr) {
    Uint16* words = nullptr;
    if (element->getUint16Array(words).bad() || words == nullptr)
      return field_error(path, "(7FE0,0010) Pixel Data", "cannot be read");
    bytes = reinterpret_cast<Uint8*>(words);
  }
  return std::make_pair(static_cast<const uint8_t*>(bytes), size_t(element->getLength()));
}

}  // namespace

absl::StatusOr<LabelVolume> read_dicom_seg(const std::string& path, const ReadLimits& limits,
                                           const RunContext& context) {
  silence_dcmtk();
  LABELMESH_ASSIGN_OR_RETURN(auto header, internal::parse_dicom_seg_header(path));
  LABELMESH_ASSIGN_OR_RETURN(auto grid, dicom_seg_grid(path, header, limits));
  LABELMESH_RETURN_IF_ERROR(context.check_stop());

  DcmFileFormat file;
  if (file.loadFile(path.c_str()).bad())
    return field_error(path, "DICOM data set", "cannot be read");
  DcmSegmentation* loaded = nullptr;
  const OFCondition condition = DcmSegmentation::loadDataset(*file.getDataset(), loaded);
  std::unique_ptr<DcmSegmentation> segmentation(loaded);
  if (condition.bad() || !segmentation) {
    return field_error(path, "DICOM SEG", absl::StrCat("DCMTK cannot read it: ", condition.text()));
  }
  // DCMTK drops segment items it cannot read; then its segment n is not the
  // file's, and names would land on the wrong labels.
  if (segmentation->getNumberOfSegments() != header.segments) {
    return field_error(path, "(0062,0002) Segment Sequence",
                       absl::StrCat(header.segments - segmentation->getNumberOfSegments(),
                                    " segment items are malformed"));
  }
  LABELMESH_ASSIGN_OR_RETURN(auto pixels, pixel_bytes(path, *file.getDataset()));
  // Named, not bound: a lambda below captures them.
  const uint8_t* const bytes = pixels.first;
  const size_t byte_count = pixels.second;
  context.report("read", 0.5);

  const uint64_t rows = header.rows, columns = header.columns;
  const uint64_t frame_pixels = rows * columns;
  const bool binary = header.bits_allocated == 1;
  const uint64_t needed =
      binary ? (frame_pixels * header.frames + 7) / 8 : frame_pixels * header.frames;
  if (byte_count < needed) {
    return field_error(path, "(7FE0,0010) Pixel Data",
                       absl::StrCat("holds ", byte_count, " bytes, ", needed, " needed"));
  }
  // A FRACTIONAL value v is inside when v / max >= threshold.
  const double least_inside = limits.fractional_threshold * header.maximum_fractional_value;

  const ImageGeometry& g = grid.geometry;
  auto labels = vtkSmartPointer<vtkUnsignedShortArray>::New();
  labels->SetNumberOfComponents(1);
  labels->SetNumberOfTuples(g.voxel_count());
  uint16_t* voxels = labels->GetPointer(0);
  std::fill(voxels, voxels + g.voxel_count(), uint16_t{0});
  auto inside = [&](uint64_t at) {
    return binary ? ((bytes[at >> 3] >> (at & 7)) & 1) != 0
                  : bytes[at] > 0 && double(bytes[at]) >= least_inside;
  };
  // Voxels two segments both claim, per pair (lower number first).
  std::map<std::pair<uint16_t, uint16_t>, uint64_t> shared;
  for (uint32_t f = 0; f < header.frames; ++f) {
    const uint16_t segment = header.frame_segments[f];
    const uint64_t slice_start = uint64_t(grid.frame_slice[f]) * frame_pixels;
    const uint64_t first = uint64_t(f) * frame_pixels;
    for (uint64_t p = 0; p < frame_pixels; ++p) {
      if (!inside(first + p)) continue;
      uint16_t& voxel = voxels[slice_start + p];
      if (voxel != 0 && voxel != segment)
        ++shared[{std::min(voxel, segment), std::max(voxel, segment)}];
      else
        voxel = segment;
    }
    if ((f & 63) == 0) {
      LABELMESH_RETURN_IF_ERROR(context.check_stop());
    }
  }
  if (!shared.empty() && !limits.separate_overlapping) {
    // The first few pairs: the message must stay short.
    constexpr size_t kPairsNamed = 10;
    std::string pairs;
    size_t named = 0;
    for (const auto& [pair, count] : shared) {
      if (named++ == kPairsNamed) {
        absl::StrAppend(&pairs, " and ", shared.size() - kPairsNamed, " more pairs");
        break;
      }
      absl::StrAppend(&pairs, pairs.empty() ? "" : ", ", "segments ", pair.first, " and ",
                      pair.second, " share ", count, " voxels");
    }
    return field_error(path, "segments",
                       absl::StrCat("overlap (", pairs,
                                    "); a label volume holds one label a voxel, so overlapping "
                                    "segments cannot be meshed together",
                                    kSeparateOverlappingHint));
  }

  LabelVolume volume;
  volume.format = ImageFormat::kDicomSeg;
  volume.file_voxel_type = binary ? "binary" : "fractional";
  volume.geometry = g;
  volume.voxels = vtkSmartPointer<vtkImageData>::New();
  volume.voxels->SetDimensions(int(g.dims[0]), int(g.dims[1]), int(g.dims[2]));
  if (shared.empty()) {
    volume.voxels->GetPointData()->SetScalars(labels);
  } else {
    labels = nullptr;  // its memory goes to the layers
    // Each segment's frames, by segment index: the grid checks that
    // segment n is item n - 1 and that every frame names one of them.
    const std::vector<int32_t> numbers(header.segment_numbers.begin(),
                                       header.segment_numbers.end());
    std::vector<std::vector<uint32_t>> frames_of(numbers.size());
    for (uint32_t f = 0; f < header.frames; ++f)
      frames_of[header.frame_segments[f] - 1].push_back(f);
    uint64_t frames_visited = 0;
    auto layers = separate_segments(
        path, numbers, numbers.size(), uint64_t(g.voxel_count()), VTK_UNSIGNED_SHORT, limits,
        [&](size_t segment, SegmentVoxelSink sink) -> absl::Status {
          for (uint32_t f : frames_of[segment]) {
            if ((frames_visited++ & 63) == 0) {
              LABELMESH_RETURN_IF_ERROR(context.check_stop());
            }
            const uint64_t slice_start = uint64_t(grid.frame_slice[f]) * frame_pixels;
            const uint64_t first = uint64_t(f) * frame_pixels;
            for (uint64_t p = 0; p < frame_pixels; ++p) {
              if (inside(first + p)) sink(segment, slice_start + p);
            }
          }
          return absl::OkStatus();
        },
        context);
    if (!layers.ok()) return layers.status();
    volume.voxels->GetPointData()->SetScalars((*layers)[0]);
    for (size_t k = 1; k < layers->size(); ++k) {
      auto image = vtkSmartPointer<vtkImageData>::New();
      image->SetDimensions(int(g.dims[0]), int(g.dims[1]), int(g.dims[2]));
      image->GetPointData()->SetScalars((*layers)[k]);
      volume.more_layers.push_back(std::move(image));
    }
  }
  for (uint16_t number : header.segment_numbers) {
    DcmSegment* segment = segmentation->getSegment(number);
    if (segment == nullptr) continue;
    volume.descriptions.push_back(describe(number, *segment));
  }
  std::sort(volume.descriptions.begin(), volume.descriptions.end(),
            [](const auto& a, const auto& b) { return a.label < b.label; });
  context.report("read", 1.0);
  return volume;
}

}  // namespace labelmesh::volume
