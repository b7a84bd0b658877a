// SPDX-License-Identifier: AGPL-3.0-or-later
// The quality report as one self-contained HTML page (report.html beside
// report.json): per-label figures and quality charts, readable offline.
#pragma once

#include <string>
#include <string_view>

#include "labelmesh/v1/report.pb.h"

namespace labelmesh {

// `text` with & < > " ' replaced by character references, safe inside HTML
// and SVG text and in quoted attribute values.
std::string html_escape(std::string_view text);

// An HTML5 page of `report`: the input's format and grid, a table of every
// label (name, voxels, output surface figures, distance to Marching Cubes,
// warnings and errors) and inline SVG charts of the surface angles and, when
// a volume mesh exists, its Table 1 quality categories. No scripts and no
// external resources; every string from the report is escaped. Never fails.
std::string report_html(const v1::Report& report);

}  // namespace labelmesh
