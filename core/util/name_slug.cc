// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/util/name_slug.h"

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

}  // namespace labelmesh
