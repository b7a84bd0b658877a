// SPDX-License-Identifier: AGPL-3.0-or-later
// What DICOM objects made from a DICOM input carry over from it: its
// patient, its study and its frame of reference, and its own identity so
// that they can reference it.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"

namespace labelmesh::dicom {

struct DicomSource {
  // Patient, General Study and Frame of Reference attributes present in the
  // input, and its Specific Character Set: (group << 16 | element, value),
  // in tag order. Values are copied, never logged.
  std::vector<std::pair<uint32_t, std::string>> attributes;
  std::string sop_class_uid;
  std::string sop_instance_uid;
  std::string series_instance_uid;
};

// Reads those attributes (not the pixel data) with DCMTK. Errors name the
// file: INVALID_ARGUMENT when it cannot be read or lacks a Study Instance
// UID, Frame of Reference UID or SOP Instance UID, which every object made
// from it needs.
absl::StatusOr<DicomSource> read_dicom_source(const std::string& path);

}  // namespace labelmesh::dicom
