// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/dicom/dicom_source.h"

#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>

#include "absl/strings/str_cat.h"

namespace labelmesh::dicom {
namespace {

// Patient module, General Study module, Frame of Reference module, and the
// character set their text is in.
const DcmTagKey kCarried[] = {DCM_SpecificCharacterSet,
                              DCM_StudyDate,
                              DCM_StudyTime,
                              DCM_AccessionNumber,
                              DCM_ReferringPhysicianName,
                              DCM_StudyDescription,
                              DCM_PatientName,
                              DCM_PatientID,
                              DCM_IssuerOfPatientID,
                              DCM_PatientBirthDate,
                              DCM_PatientSex,
                              DCM_StudyInstanceUID,
                              DCM_StudyID,
                              DCM_FrameOfReferenceUID,
                              DCM_PositionReferenceIndicator};

// Values longer than this stay on disk while the header is read.
constexpr Uint32 kLoadedValueBytes = 4096;

std::string text_of(DcmDataset& dataset, const DcmTagKey& tag) {
  OFString value;
  if (dataset.findAndGetOFStringArray(tag, value).bad()) return {};
  return std::string(value.c_str(), value.length());
}

}  // namespace

absl::StatusOr<DicomSource> read_dicom_source(const std::string& path) {
  DcmFileFormat file;
  if (file.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, kLoadedValueBytes).bad())
    return absl::InvalidArgumentError(absl::StrCat(path, ": DICOM data set: cannot be read"));
  DcmDataset& dataset = *file.getDataset();
  DicomSource source;
  for (const DcmTagKey& tag : kCarried) {
    if (!dataset.tagExists(tag)) continue;
    source.attributes.emplace_back(uint32_t(tag.getGroup()) << 16 | tag.getElement(),
                                   text_of(dataset, tag));
  }
  source.sop_class_uid = text_of(dataset, DCM_SOPClassUID);
  source.sop_instance_uid = text_of(dataset, DCM_SOPInstanceUID);
  source.series_instance_uid = text_of(dataset, DCM_SeriesInstanceUID);
  const std::pair<DcmTagKey, const char*> needed[] = {
      {DCM_StudyInstanceUID, "(0020,000D) Study Instance UID"},
      {DCM_FrameOfReferenceUID, "(0020,0052) Frame of Reference UID"},
      {DCM_SOPInstanceUID, "(0008,0018) SOP Instance UID"}};
  for (const auto& [tag, name] : needed) {
    if (text_of(dataset, tag).empty())
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": ", name, ": missing, and DICOM output made from the file needs it"));
  }
  return source;
}

}  // namespace labelmesh::dicom
