// SPDX-License-Identifier: AGPL-3.0-or-later
// What a file says a label is: its name, display colour and coded meaning
// (DICOM SEG segments; other formats' label tables).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace labelmesh::volume {

// A coded concept, as DICOM writes one: scheme (SCT, DCM, ...), value, meaning.
struct CodedConcept {
  std::string scheme;
  std::string value;
  std::string meaning;
  bool empty() const { return scheme.empty() && value.empty() && meaning.empty(); }
};

struct LabelDescription {
  int32_t label = 0;
  std::string name;
  // sRGB, 0-255.
  std::optional<std::array<uint8_t, 3>> colour;
  CodedConcept category;
  CodedConcept type;
};

using LabelDescriptions = std::vector<LabelDescription>;

// A description with a name (and a colour) only.
inline LabelDescription named_label(int32_t label, std::string name,
                                    std::optional<std::array<uint8_t, 3>> colour = {}) {
  LabelDescription description;
  description.label = label;
  description.name = std::move(name);
  description.colour = colour;
  return description;
}

}  // namespace labelmesh::volume
