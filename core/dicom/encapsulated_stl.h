// SPDX-License-Identifier: AGPL-3.0-or-later
// A surface as a DICOM Encapsulated STL object (PS3.3 A.85), so that it can
// be stored in a PACS beside the segmentation it was made from.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "core/dicom/dicom_source.h"

namespace labelmesh::dicom {

// The new series the surfaces of one run go to.
struct DicomSeries {
  std::string series_instance_uid;
  int32_t series_number = 0;
  std::string date;  // YYYYMMDD
  std::string time;  // HHMMSS
};

// A new series UID (DCMTK's UID root), made now.
DicomSeries new_surface_series();

// Writes `stl` (binary STL bytes, coordinates in the patient frame, mm) to
// `path` as Encapsulated STL: the source's patient, study and frame of
// reference, the series, modality M3D, units mm (UCUM), `title` (UTF-8) as
// the document title, and a reference to the source instance. Dates and
// times are UTC and say so. Errors name the file.
absl::Status write_encapsulated_stl(const std::string& stl, const std::string& path,
                                    const DicomSource& source, const DicomSeries& series,
                                    int32_t instance_number, const std::string& title);

}  // namespace labelmesh::dicom
