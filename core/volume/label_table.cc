// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume/label_table.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/header/header_checks.h"
#include "core/util/status_macros.h"
#include "core/util/utf8.h"

namespace labelmesh::volume {
namespace {

using internal::field_error;

constexpr uint64_t kMostTableBytes = uint64_t{4} << 20;
constexpr size_t kMostEntries = 65536;

absl::StatusOr<std::array<uint8_t, 3>> colour_of(const std::string& path, const std::string& where,
                                                 const std::vector<absl::string_view>& values) {
  std::array<uint8_t, 3> colour{};
  for (int c = 0; c < 3; ++c) {
    int value = 0;
    if (!absl::SimpleAtoi(values[c], &value) || value < 0 || value > 255)
      return field_error(path, where, "colour components must be whole numbers 0-255");
    colour[c] = static_cast<uint8_t>(value);
  }
  return colour;
}

absl::Status add_entry(const std::string& path, const std::string& where, int64_t label,
                       std::string name, std::optional<std::array<uint8_t, 3>> colour,
                       LabelDescriptions& table) {
  if (label < 0 || label > std::numeric_limits<int32_t>::max())
    return field_error(path, where, "label outside 0 to 2^31 - 1");
  if (label == 0) return absl::OkStatus();  // the background
  if (table.size() >= kMostEntries)
    return field_error(path, where, absl::StrCat("more than ", kMostEntries, " labels"));
  for (const auto& earlier : table) {
    if (earlier.label == label)
      return field_error(path, where, absl::StrCat("label ", label, " is named twice"));
  }
  LabelDescription entry;
  entry.label = static_cast<int32_t>(label);
  entry.name = valid_utf8(name);
  entry.colour = colour;
  table.push_back(std::move(entry));
  return absl::OkStatus();
}

// ITK-SNAP or FreeSurfer lines.
absl::StatusOr<LabelDescriptions> read_text_table(const std::string& path,
                                                  const std::string& text) {
  LabelDescriptions table;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    const std::string where = absl::StrCat("line ", line_number);
    // '#' starts a comment, but not inside a quoted ITK-SNAP name.
    const size_t hash = line.find('#');
    if (hash != absl::string_view::npos && hash < line.find('"')) line = line.substr(0, hash);
    line = absl::StripAsciiWhitespace(line);
    if (line.empty()) continue;
    std::string name;
    absl::string_view numbers = line;
    const size_t quote = line.find('"');
    if (quote != absl::string_view::npos) {  // ITK-SNAP: the name last, quoted
      const size_t end = line.rfind('"');
      if (end == quote) return field_error(path, where, "a label name without its closing quote");
      name = std::string(line.substr(quote + 1, end - quote - 1));
      numbers = line.substr(0, quote);
    }
    std::vector<absl::string_view> fields =
        absl::StrSplit(numbers, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    int64_t label = 0;
    if (fields.empty() || !absl::SimpleAtoi(fields[0], &label))
      return field_error(path, where, "does not start with a label number");
    std::vector<absl::string_view> rgb;
    if (quote != absl::string_view::npos) {
      if (fields.size() < 4) return field_error(path, where, "needs IDX R G B before the name");
      rgb = {fields[1], fields[2], fields[3]};
    } else {  // FreeSurfer: IDX NAME R G B [A]
      if (fields.size() < 5) return field_error(path, where, "needs IDX NAME R G B");
      name = std::string(fields[1]);
      rgb = {fields[2], fields[3], fields[4]};
    }
    LABELMESH_ASSIGN_OR_RETURN(auto colour, colour_of(path, where, rgb));
    LABELMESH_RETURN_IF_ERROR(add_entry(path, where, label, std::move(name), colour, table));
  }
  return table;
}

// The deepest nesting a label table needs is 3 ({"5": {"color": [r, g, b]}});
// protobuf's parser takes minutes over tens of thousands of levels.
constexpr int kMostJsonDepth = 8;

// Whether the objects and arrays of `text` (outside strings) nest deeper
// than `most`: one pass, ending at the first level too deep.
bool nests_deeper_than(std::string_view text, int most) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > most) return true;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return false;
}

absl::StatusOr<LabelDescriptions> read_json_table(const std::string& path,
                                                  const std::string& text) {
  if (nests_deeper_than(text, kMostJsonDepth))
    return field_error(path, "JSON", absl::StrCat("nests deeper than ", kMostJsonDepth, " levels"));
  google::protobuf::Struct map;
  if (!google::protobuf::util::JsonStringToMessage(text, &map).ok())
    return field_error(path, "JSON", "is not a JSON object");
  LabelDescriptions table;
  for (const auto& [key, value] : map.fields()) {
    int64_t label = 0;
    if (!absl::SimpleAtoi(key, &label))
      return field_error(path, "JSON", "a key is not a label number");
    const std::string where = absl::StrCat("label ", label);
    std::string name;
    std::optional<std::array<uint8_t, 3>> colour;
    if (value.has_string_value()) {
      name = value.string_value();
    } else if (value.has_struct_value()) {
      const auto& fields = value.struct_value().fields();
      if (auto it = fields.find("name"); it != fields.end()) name = it->second.string_value();
      auto it = fields.find("color");
      if (it == fields.end()) it = fields.find("colour");
      if (it != fields.end()) {
        const auto& list = it->second.list_value().values();
        std::array<uint8_t, 3> rgb{};
        if (list.size() != 3) return field_error(path, where, "a colour needs three components");
        for (int c = 0; c < 3; ++c) {
          const double v = list[c].number_value();
          if (!(v >= 0 && v <= 255) || v != std::floor(v))
            return field_error(path, where, "colour components must be whole numbers 0-255");
          rgb[c] = static_cast<uint8_t>(v);
        }
        colour = rgb;
      }
    } else {
      return field_error(path, where, "must be a name or an object with a name");
    }
    LABELMESH_RETURN_IF_ERROR(add_entry(path, where, label, std::move(name), colour, table));
  }
  return table;
}

}  // namespace

absl::StatusOr<LabelDescriptions> read_label_table(const std::string& path) {
  LABELMESH_ASSIGN_OR_RETURN(auto size, internal::file_size(path));
  if (size > kMostTableBytes)
    return field_error(path, "file", absl::StrCat("over ", kMostTableBytes, " bytes"));
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.eof() && in.fail()) return field_error(path, "file", "cannot be read");
  const absl::string_view start = absl::StripLeadingAsciiWhitespace(text);
  auto table = !start.empty() && start.front() == '{' ? read_json_table(path, text)
                                                      : read_text_table(path, text);
  if (!table.ok()) return table.status();
  std::sort(table->begin(), table->end(),
            [](const auto& a, const auto& b) { return a.label < b.label; });
  return table;
}

void apply_label_table(const LabelDescriptions& table, LabelDescriptions& descriptions) {
  for (const auto& entry : table) {
    auto it = std::find_if(descriptions.begin(), descriptions.end(),
                           [&](const auto& d) { return d.label == entry.label; });
    if (it == descriptions.end()) {
      descriptions.push_back(entry);
      continue;
    }
    if (!entry.name.empty()) it->name = entry.name;
    if (entry.colour) it->colour = entry.colour;
  }
  std::sort(descriptions.begin(), descriptions.end(),
            [](const auto& a, const auto& b) { return a.label < b.label; });
}

}  // namespace labelmesh::volume
