// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/volume_format.h"

namespace labelmesh::volume_mesh {

std::optional<VolumeFormat> volume_format_from_name(std::string_view name) {
  for (VolumeFormat format : all_volume_formats()) {
    if (volume_format_name(format) == name) return format;
  }
  return std::nullopt;
}

std::string_view volume_format_name(VolumeFormat format) {
  switch (format) {
    case VolumeFormat::kVtu:
      return "vtu";
    case VolumeFormat::kMsh:
      return "msh";
    case VolumeFormat::kMedit:
      return "mesh";
    case VolumeFormat::kAbaqus:
      return "inp";
    case VolumeFormat::kTetgen:
      return "node";
    case VolumeFormat::kXdmf:
      return "xdmf";
  }
  return "unknown";
}

const std::vector<VolumeFormat>& all_volume_formats() {
  static const std::vector<VolumeFormat> kAll{VolumeFormat::kVtu,    VolumeFormat::kMsh,
                                              VolumeFormat::kMedit,  VolumeFormat::kAbaqus,
                                              VolumeFormat::kTetgen, VolumeFormat::kXdmf};
  return kAll;
}

}  // namespace labelmesh::volume_mesh
