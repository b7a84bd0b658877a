// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/surface_format.h"

namespace labelmesh::surface {

std::optional<SurfaceFormat> surface_format_from_name(std::string_view name) {
  for (SurfaceFormat format : all_surface_formats()) {
    if (surface_format_name(format) == name) return format;
  }
  return std::nullopt;
}

std::string_view surface_format_name(SurfaceFormat format) {
  switch (format) {
    case SurfaceFormat::kStl:
      return "stl";
    case SurfaceFormat::kPly:
      return "ply";
    case SurfaceFormat::kObj:
      return "obj";
    case SurfaceFormat::kOff:
      return "off";
    case SurfaceFormat::kVtp:
      return "vtp";
  }
  return "unknown";
}

const std::vector<SurfaceFormat>& all_surface_formats() {
  static const std::vector<SurfaceFormat> kAll{SurfaceFormat::kStl, SurfaceFormat::kPly,
                                               SurfaceFormat::kObj, SurfaceFormat::kOff,
                                               SurfaceFormat::kVtp};
  return kAll;
}

}  // namespace labelmesh::surface
