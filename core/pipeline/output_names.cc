// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/output_names.h"

#include "core/util/text.h"

namespace labelmesh {

std::string surface_file_stem(int32_t label, const volume::LabelDescriptions& descriptions) {
  std::string stem = cat("surface-label", label);
  for (const auto& description : descriptions) {
    if (description.label != label) continue;
    if (const std::string slug = name_slug(description.name); !slug.empty()) stem += cat("-", slug);
    break;
  }
  return stem;
}

}  // namespace labelmesh
