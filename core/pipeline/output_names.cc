// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/output_names.h"

#include "core/util/text.h"

namespace labelmesh {

std::string name_slug(std::string_view name) {
  constexpr size_t kMostCharacters = 48;
  std::string slug;
  bool gap = false;
  for (char c : name) {
    const bool letter = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    const bool upper = c >= 'A' && c <= 'Z';
    if (!letter && !upper) {
      gap = !slug.empty();
      continue;
    }
    if (gap) {
      if (slug.size() + 1 >= kMostCharacters) break;
      slug.push_back('-');
      gap = false;
    }
    if (slug.size() >= kMostCharacters) break;
    slug.push_back(upper ? char(c - 'A' + 'a') : c);
  }
  return slug;
}

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
