// SPDX-License-Identifier: AGPL-3.0-or-later
// The quality report as one self-contained HTML page (report.html beside
// report.json): per-label figures and quality charts, readable offline.
#pragma once

#include <string>
#include <string_view>

#include "core/pipeline/surface_picture.h"
#include "labelmesh/v1/report.pb.h"

namespace labelmesh {

// `text` with & < > " ' replaced by character references, safe inside HTML
// and SVG text and in quoted attribute values.
std::string html_escape(std::string_view text);

// An HTML5 page of `report`: the input's file, digest, format and grid, when
// it was made, a table of every label (name, voxels, output surface figures,
// distance to Marching Cubes, warnings and errors), the pictures of the
// surfaces when given, inline SVG charts of the surface angles and, when a
// volume mesh exists, its figures (by mesher) and Table 1 quality
// categories. No scripts and no external resources (pictures are inline
// PNG); every string from the report is escaped. Never fails.
std::string report_html(const v1::Report& report, const SurfacePictures& pictures = {});

}  // namespace labelmesh
