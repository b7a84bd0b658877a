// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/dicom/encapsulated_stl.h"

#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <algorithm>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace labelmesh::dicom {
namespace {

std::string new_uid() {
  char uid[100];
  return dcmGenerateUniqueIdentifier(uid, SITE_INSTANCE_UID_ROOT);
}

// Fills `item` with the attributes, stopping at the first failure.
struct Writer {
  DcmItem& item;
  OFCondition status = EC_Normal;
  Writer& put(const DcmTagKey& tag, const std::string& value) {
    if (status.good()) status = item.putAndInsertString(tag, value.c_str());
    return *this;
  }
};

}  // namespace

DicomSeries new_surface_series() {
  const absl::Time now = absl::Now();
  return {new_uid(), 9001, absl::FormatTime("%Y%m%d", now, absl::UTCTimeZone()),
          absl::FormatTime("%H%M%S", now, absl::UTCTimeZone())};
}

absl::Status write_encapsulated_stl(const std::string& stl, const std::string& path,
                                    const DicomSource& source, const DicomSeries& series,
                                    int32_t instance_number, const std::string& title) {
  DcmFileFormat file;
  DcmDataset& dataset = *file.getDataset();
  Writer writer{dataset};
  for (const auto& [tag, value] : source.attributes)
    writer.put(DcmTagKey(Uint16(tag >> 16), Uint16(tag & 0xFFFF)), value);
  // Label names are UTF-8: with one outside ASCII the object's text becomes
  // UTF-8 (ISO_IR 192), the copied values converted; where DCMTK cannot
  // convert them the title falls back to ASCII.
  std::string document_title = title;
  const bool ascii = std::all_of(title.begin(), title.end(),
                                 [](char c) { return static_cast<unsigned char>(c) < 0x80; });
  if (!ascii && writer.status.good() && dataset.convertToUTF8().bad())
    document_title = absl::StrCat("label ", instance_number);
  writer.put(DCM_SOPClassUID, UID_EncapsulatedSTLStorage)
      .put(DCM_SOPInstanceUID, new_uid())
      .put(DCM_Modality, "M3D")
      .put(DCM_SeriesInstanceUID, series.series_instance_uid)
      .put(DCM_SeriesNumber, std::to_string(series.series_number))
      .put(DCM_SeriesDescription, "labelmesh surfaces")
      .put(DCM_Manufacturer, "labelmesh")
      .put(DCM_ManufacturerModelName, "labelmesh")
      .put(DCM_DeviceSerialNumber, "0")
      .put(DCM_SoftwareVersions, LABELMESH_VERSION)
      .put(DCM_InstanceNumber, std::to_string(instance_number))
      .put(DCM_ContentDate, series.date)
      .put(DCM_ContentTime, series.time)
      .put(DCM_TimezoneOffsetFromUTC, "+0000")
      .put(DCM_AcquisitionDateTime, "")
      .put(DCM_BurnedInAnnotation, "NO")
      .put(DCM_DocumentTitle, document_title)
      .put(DCM_MIMETypeOfEncapsulatedDocument, "model/stl");
  if (!dataset.tagExists(DCM_PositionReferenceIndicator))
    writer.put(DCM_PositionReferenceIndicator, "");
  if (writer.status.good()) writer.status = dataset.insertEmptyElement(DCM_ConceptNameCodeSequence);
  DcmItem* units = nullptr;
  if (writer.status.good())
    writer.status = dataset.findOrCreateSequenceItem(DCM_MeasurementUnitsCodeSequence, units, 0);
  if (writer.status.good()) {
    writer.status = Writer{*units}
                        .put(DCM_CodeValue, "mm")
                        .put(DCM_CodingSchemeDesignator, "UCUM")
                        .put(DCM_CodeMeaning, "mm")
                        .status;
  }
  DcmItem* derived_from = nullptr;
  if (writer.status.good())
    writer.status = dataset.findOrCreateSequenceItem(DCM_SourceInstanceSequence, derived_from, 0);
  if (writer.status.good()) {
    writer.status = Writer{*derived_from}
                        .put(DCM_ReferencedSOPClassUID, source.sop_class_uid)
                        .put(DCM_ReferencedSOPInstanceUID, source.sop_instance_uid)
                        .status;
  }
  // The value is padded to an even length; the length attribute keeps the
  // document's own.
  std::vector<Uint8> bytes(stl.begin(), stl.end());
  if (bytes.size() % 2 != 0) bytes.push_back(0);
  if (writer.status.good())
    writer.status = dataset.putAndInsertUint8Array(DCM_EncapsulatedDocument, bytes.data(),
                                                   static_cast<unsigned long>(bytes.size()));
  if (writer.status.good())
    writer.status = dataset.putAndInsertUint32(DCM_EncapsulatedDocumentLength, Uint32(stl.size()));
  if (writer.status.bad())
    return absl::InternalError(
        absl::StrCat(path, ": cannot make the DICOM object: ", writer.status.text()));
  const OFCondition saved = file.saveFile(path.c_str(), EXS_LittleEndianExplicit);
  if (saved.bad()) return absl::InternalError(absl::StrCat(path, ": cannot write: ", saved.text()));
  return absl::OkStatus();
}

}  // namespace labelmesh::dicom
