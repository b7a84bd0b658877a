// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/header/slicer_segments.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/text.h"
#include "core/util/utf8.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

constexpr std::string_view kPrefix = "Segment";

// The values of one segment's keys that are used; null when absent.
struct SegmentKeys {
  const std::string* id = nullptr;
  const std::string* name = nullptr;
  const std::string* colour = nullptr;
  const std::string* value = nullptr;
  const std::string* layer = nullptr;
  const std::string* tags = nullptr;
};

std::string key_name(int index, std::string_view suffix) {
  return cat(kPrefix, index, "_", suffix);
}

// Splits "Segment<i>_<suffix>"; false for any other key (Segmentation_*, ...).
bool split_segment_key(std::string_view key, std::string_view& digits, std::string_view& suffix) {
  if (!key.starts_with(kPrefix)) return false;
  key.remove_prefix(kPrefix.size());
  const size_t underscore = key.find('_');
  if (underscore == 0 || underscore == std::string_view::npos) return false;
  digits = key.substr(0, underscore);
  suffix = key.substr(underscore + 1);
  if (digits.size() > 1 && digits[0] == '0') return false;  // one spelling per index
  for (char c : digits) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

void keep_key(std::string_view suffix, const std::string& value, SegmentKeys& keys) {
  if (suffix == "ID") keys.id = &value;
  if (suffix == "Name") keys.name = &value;
  if (suffix == "Color") keys.colour = &value;
  if (suffix == "LabelValue") keys.value = &value;
  if (suffix == "Layer") keys.layer = &value;
  if (suffix == "Tags") keys.tags = &value;
}

// Every Segment<i>_ key, by segment index, bounded before anything grows.
absl::StatusOr<std::map<int, SegmentKeys>> group_keys(
    std::string_view path, const std::map<std::string, std::string, std::less<>>& key_values) {
  std::map<int, SegmentKeys> segments;
  for (const auto& [key, value] : key_values) {
    std::string_view digits, suffix;
    if (!split_segment_key(key, digits, suffix)) continue;
    int index = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (error != std::errc() || end != digits.data() + digits.size() ||
        index >= kMostSlicerSegments) {
      return field_error(path, "Segment<i>_ keys",
                         cat("more than ", kMostSlicerSegments, " segments"));
    }
    keep_key(suffix, value, segments[index]);
  }
  int expected = 0;
  for (const auto& [index, keys] : segments) {
    if (index != expected) {
      return field_error(
          path, key_name(expected, "ID"),
          cat("is missing: segments must be numbered 0 to ", segments.size() - 1, " without gaps"));
    }
    ++expected;
  }
  return segments;
}

// NRRD key/value escapes: "\n" a newline, "\\" a backslash.
std::string unescape(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size() && (text[i + 1] == 'n' || text[i + 1] == '\\')) {
      out.push_back(text[++i] == 'n' ? '\n' : '\\');
    } else {
      out.push_back(text[i]);
    }
  }
  return out;
}

// The Name (else the ID): bounded, UTF-8, no control characters.
absl::StatusOr<std::string> segment_name(std::string_view path, int index,
                                         const SegmentKeys& keys) {
  const std::string* raw = keys.name != nullptr ? keys.name : keys.id;
  if (raw == nullptr) return std::string();
  const std::string field = key_name(index, keys.name != nullptr ? "Name" : "ID");
  const std::string name(trim(unescape(*raw)));
  if (name.size() > kMostSlicerNameBytes) {
    return field_error(path, field, cat("is longer than ", kMostSlicerNameBytes, " bytes"));
  }
  if (valid_utf8(name) != name) {
    return field_error(path, field, "is not UTF-8 text without control characters");
  }
  return name;
}

// "r g b", each 0-1, as 0-255 sRGB.
absl::StatusOr<std::array<uint8_t, 3>> segment_colour(std::string_view path, int index,
                                                      const std::string& text) {
  const std::string field = key_name(index, "Color");
  LABELMESH_ASSIGN_OR_RETURN(auto values, internal::parse_numbers(path, field, text, 3));
  std::array<uint8_t, 3> colour{};
  for (int c = 0; c < 3; ++c) {
    const double v = values[c];
    if (!(v >= 0 && v <= 1)) {
      return field_error(path, field, "components must be numbers from 0 to 1");
    }
    colour[c] = static_cast<uint8_t>(std::lround(v * 255));
  }
  return colour;
}

// A whole number in [least, most], or the error naming the key.
absl::StatusOr<int64_t> whole_number(std::string_view path, const std::string& field,
                                     std::string_view text, int64_t least, int64_t most) {
  int64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < least || value > most) {
    return field_error(path, field, cat("must be a whole number from ", least, " to ", most));
  }
  return value;
}

// Splits at every `separator`, keeping empty pieces (terminology entries
// leave fields empty: "~^^~").
std::vector<std::string_view> split_all(std::string_view text, char separator) {
  std::vector<std::string_view> pieces;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(separator, start);
    pieces.push_back(text.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos) return pieces;
    start = end + 1;
  }
}

// "scheme^value^meaning"; empty when malformed or too long.
CodedConcept coded_concept(std::string_view text) {
  const auto parts = split_all(text, '^');
  if (parts.size() != 3) return {};
  for (std::string_view part : parts) {
    if (part.size() > kMostSlicerNameBytes) return {};
  }
  return {valid_utf8(parts[0]), valid_utf8(parts[1]), valid_utf8(parts[2])};
}

// Category and type from the "TerminologyEntry:" tag of Segment<i>_Tags:
// "context~category~type~modifier~anatomic context~region~region modifier".
// Optional: anything malformed leaves the codes empty.
void read_terminology(std::string_view tags, LabelDescription& description) {
  constexpr std::string_view kTag = "TerminologyEntry:";
  for (std::string_view tag : split_all(tags, '|')) {
    if (!tag.starts_with(kTag)) continue;
    const auto entries = split_all(tag.substr(kTag.size()), '~');
    if (entries.size() < 3) return;
    description.category = coded_concept(entries[1]);
    description.type = coded_concept(entries[2]);
    return;
  }
}

absl::StatusOr<SlicerSegment> parse_segment(std::string_view path, int index,
                                            const SegmentKeys& keys, int64_t layers,
                                            bool layer_per_segment) {
  SlicerSegment segment;
  LABELMESH_ASSIGN_OR_RETURN(auto name, segment_name(path, index, keys));
  segment.description.name = std::move(name);
  if (keys.colour != nullptr) {
    LABELMESH_ASSIGN_OR_RETURN(auto colour, segment_colour(path, index, *keys.colour));
    segment.description.colour = colour;
  }
  if (keys.value != nullptr) {
    LABELMESH_ASSIGN_OR_RETURN(auto value,
                               whole_number(path, key_name(index, "LabelValue"), *keys.value, 1,
                                            std::numeric_limits<int32_t>::max()));
    segment.value = static_cast<int32_t>(value);
  }
  if (keys.layer != nullptr) {
    LABELMESH_ASSIGN_OR_RETURN(
        auto layer, whole_number(path, key_name(index, "Layer"), *keys.layer, 0, layers - 1));
    segment.layer = static_cast<int>(layer);
  } else if (layer_per_segment) {
    segment.layer = index;
  }
  if (keys.tags != nullptr) read_terminology(*keys.tags, segment.description);
  return segment;
}

// One layer cannot give one value to two segments.
absl::Status check_distinct_values(std::string_view path,
                                   const std::vector<SlicerSegment>& segments) {
  std::map<std::pair<int, int32_t>, size_t> owner;
  for (size_t i = 0; i < segments.size(); ++i) {
    const auto [at, added] = owner.emplace(std::pair{segments[i].layer, segments[i].value}, i);
    if (!added) {
      return field_error(
          path, key_name(static_cast<int>(i), "LabelValue"),
          cat("is also the value of segment ", at->second, " in layer ", segments[i].layer));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<SlicerSegment>> parse_slicer_segments(
    std::string_view path, const std::map<std::string, std::string, std::less<>>& key_values,
    int64_t layers) {
  LABELMESH_ASSIGN_OR_RETURN(auto grouped, group_keys(path, key_values));
  const bool layer_per_segment = layers > 1 && layers == static_cast<int64_t>(grouped.size());
  std::vector<SlicerSegment> segments;
  segments.reserve(grouped.size());
  for (const auto& [index, keys] : grouped) {
    LABELMESH_ASSIGN_OR_RETURN(auto segment,
                               parse_segment(path, index, keys, layers, layer_per_segment));
    segments.push_back(std::move(segment));
  }
  LABELMESH_RETURN_IF_ERROR(check_distinct_values(path, segments));
  const std::vector<int32_t> labels = slicer_labels(segments);
  for (size_t i = 0; i < segments.size(); ++i) segments[i].description.label = labels[i];
  return segments;
}

std::vector<int32_t> slicer_labels(const std::vector<SlicerSegment>& segments) {
  std::set<int32_t> values;
  for (const auto& segment : segments) values.insert(segment.value);
  std::vector<int32_t> labels;
  labels.reserve(segments.size());
  const bool keep_values = values.size() == segments.size();
  for (size_t i = 0; i < segments.size(); ++i) {
    labels.push_back(keep_values ? segments[i].value : static_cast<int32_t>(i + 1));
  }
  return labels;
}

}  // namespace labelmesh::volume
