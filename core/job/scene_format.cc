// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/job/scene_format.h"

namespace labelmesh {

std::optional<SceneFormat> scene_format_from_name(std::string_view name) {
  for (auto format : {SceneFormat::kVtm, SceneFormat::kVti, SceneFormat::kMha}) {
    if (name == scene_format_name(format)) return format;
  }
  return std::nullopt;
}

std::string_view scene_format_name(SceneFormat format) {
  switch (format) {
    case SceneFormat::kVtm:
      return "vtm";
    case SceneFormat::kVti:
      return "vti";
    case SceneFormat::kMha:
      return "mha";
  }
  return "";
}

std::string_view scene_file_name(SceneFormat format) {
  switch (format) {
    case SceneFormat::kVtm:
      return "surfaces.vtm";
    case SceneFormat::kVti:
      return "labels.vti";
    case SceneFormat::kMha:
      return "labels.mha";
  }
  return "";
}

}  // namespace labelmesh
