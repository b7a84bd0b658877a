// SPDX-License-Identifier: AGPL-3.0-or-later
// Label names and colours from a table beside the volume: an ITK-SNAP label
// description file, a FreeSurfer-style colour table, or a JSON map.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/header/label_description.h"

namespace labelmesh::volume {

// The format is told by the content:
// - ITK-SNAP: `IDX R G B A VIS MSH "NAME"` (the name in double quotes);
// - FreeSurfer: `IDX NAME R G B A`;
// - JSON (the file starts with '{'): {"5": "liver"} or
//   {"5": {"name": "liver", "color": [221, 130, 101]}}.
// '#' starts a comment in the text formats. Label 0 (the background) is
// skipped. Errors are INVALID_ARGUMENT naming the file and line.
absl::StatusOr<LabelDescriptions> read_label_table(const std::string& path);

// Names and colours from `table` over those the volume gave.
void apply_label_table(const LabelDescriptions& table, LabelDescriptions& descriptions);

}  // namespace labelmesh::volume
