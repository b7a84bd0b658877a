// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/report_html.h"

#include <algorithm>
#include <vector>

#include "absl/strings/escaping.h"
#include "core/pipeline/report.h"
#include "core/util/text.h"

namespace labelmesh {
namespace {

// Shown where a figure does not apply (no surface, not measured).
constexpr std::string_view kNone = "&mdash;";

// Inline so the page needs nothing beside it; system fonts only.
constexpr std::string_view kStyle = R"(
body { font-family: sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.swatch { display: inline-block; width: 0.9em; height: 0.9em; margin-right: 0.4em;
          border: 1px solid #444; vertical-align: middle; }
.warning { color: #8a5a00; }
.error { color: #b00020; }
figure { margin: 1em 0; }
figcaption { font-weight: bold; margin-bottom: 0.3em; }
div.labels { display: flex; flex-wrap: wrap; gap: 0.5em; }
figure.label { margin: 0; width: 128px; }
figure.label figcaption { font-weight: normal; font-size: 0.8em; }
)";

std::string fixed(double value, int decimals) { return format_fixed(value, decimals); }

// "a x b x c" of a repeated field, each with `decimals` digits.
template <typename Field>
std::string triple(const Field& values, int decimals) {
  std::string out;
  for (int i = 0; i < values.size(); ++i) {
    if (i > 0) out += " &times; ";
    out += fixed(static_cast<double>(values[i]), decimals);
  }
  return out.empty() ? std::string(kNone) : out;
}

// At most `bytes` bytes of `text`, cut before a UTF-8 character, for chart labels.
std::string shorten(std::string_view text, size_t bytes) {
  if (text.size() <= bytes) return std::string(text);
  size_t end = bytes;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return cat(text.substr(0, end), "\xE2\x80\xA6");  // U+2026 ellipsis.
}

// CSS colour of a label's sRGB colour, or empty when it has none.
std::string label_colour(const v1::LabelSummary& label) {
  if (label.colour_rgb_size() != 3) return "";
  const auto c = [&](int i) { return std::min<uint32_t>(label.colour_rgb(i), 255); };
  return cat("rgb(", c(0), ",", c(1), ",", c(2), ")");
}

// --- Charts: horizontal bars from `from` to `to` on an axis 0..axis_max.

struct Bar {
  std::string name;    // left of the bar (escaped when drawn)
  double from = 0;     // where the bar starts, in axis units
  double to = 0;       // where it ends
  std::string value;   // printed after the bar
  std::string colour;  // CSS colour
};

struct Chart {
  std::string title;
  std::string axis;  // the axis's quantity and unit
  double axis_max = 1;
  std::vector<Bar> bars;
};

constexpr double kNameWidth = 190, kPlotWidth = 400, kValueWidth = 150;
constexpr double kRowHeight = 24, kTop = 8, kAxisHeight = 36;

std::string svg_axis(const Chart& chart, double y) {
  const int decimals = chart.axis_max >= 10 ? 0 : 2;
  std::string out = cat("<line x1=\"", kNameWidth, "\" y1=\"", y, "\" x2=\"",
                        kNameWidth + kPlotWidth, "\" y2=\"", y, "\" stroke=\"#444\"/>\n");
  for (int tick = 0; tick <= 4; ++tick) {
    const double x = kNameWidth + kPlotWidth * tick / 4;
    out +=
        cat("<line x1=\"", x, "\" y1=\"", kTop, "\" x2=\"", x, "\" y2=\"", y + 4,
            "\" stroke=\"#ddd\"/>\n<text x=\"", x, "\" y=\"", y + 16, "\" text-anchor=\"middle\">",
            fixed(chart.axis_max * tick / 4, decimals), "</text>\n");
  }
  out += cat("<text x=\"", kNameWidth + kPlotWidth / 2, "\" y=\"", y + 32,
             "\" text-anchor=\"middle\">", html_escape(chart.axis), "</text>\n");
  return out;
}

std::string svg_bar(const Bar& bar, double axis_max, double y) {
  const auto at = [&](double v) {
    return kNameWidth + kPlotWidth * std::clamp(v / axis_max, 0.0, 1.0);
  };
  const double x0 = at(std::min(bar.from, bar.to)), x1 = at(std::max(bar.from, bar.to));
  const double width = std::max(x1 - x0, 1.0);  // A zero bar still shows where it is.
  const std::string name = html_escape(shorten(bar.name, 28));
  return cat("<text x=\"", kNameWidth - 8, "\" y=\"", y + 13, "\" text-anchor=\"end\">", name,
             "</text>\n<rect x=\"", x0, "\" y=\"", y + 2, "\" width=\"", width,
             "\" height=\"16\" fill=\"", bar.colour, "\"><title>", name, ": ",
             html_escape(bar.value), "</title></rect>\n<text x=\"", x0 + width + 6, "\" y=\"",
             y + 13, "\">", html_escape(bar.value), "</text>\n");
}

// One <figure> holding one inline SVG.
std::string svg_chart(const Chart& chart) {
  const double axis_max = chart.axis_max > 0 ? chart.axis_max : 1;
  const double axis_y = kTop + kRowHeight * static_cast<double>(chart.bars.size());
  const double width = kNameWidth + kPlotWidth + kValueWidth;
  std::string out = cat("<figure>\n<figcaption>", html_escape(chart.title), "</figcaption>\n",
                        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", width, "\" height=\"",
                        axis_y + kAxisHeight, "\" viewBox=\"0 0 ", width, " ", axis_y + kAxisHeight,
                        "\" font-family=\"sans-serif\" font-size=\"12\" role=\"img\">\n<title>",
                        html_escape(chart.title), "</title>\n");
  out += svg_axis(chart, axis_y);
  for (size_t i = 0; i < chart.bars.size(); ++i)
    out += svg_bar(chart.bars[i], axis_max, kTop + kRowHeight * static_cast<double>(i));
  return out + "</svg>\n</figure>\n";
}

// --- Report lookups.

const v1::LabelSummary* find_label(const v1::Report& report, int32_t label) {
  for (const auto& entry : report.input().labels())
    if (entry.label() == label) return &entry;
  return nullptr;
}

// The label's delivered surface, else its last stage (failed, or with
// nothing left to mesh); null when the label was not meshed.
const v1::SurfaceSummary* final_surface(const v1::Report& report, int32_t label) {
  const v1::SurfaceSummary* last = nullptr;
  for (const auto& s : report.surfaces()) {
    if (s.label() != label) continue;
    if (s.output()) return &s;
    last = &s;
  }
  return last;
}

std::string label_name(const v1::Report& report, int32_t label) {
  const auto* entry = find_label(report, label);
  return entry && !entry->name().empty() ? cat(label, " ", entry->name()) : cat("label ", label);
}

// --- Page sections.

std::string input_section(const v1::Report& report) {
  const auto& input = report.input();
  return cat("<h2>Input</h2>\n<table>\n", "<tr><th>Format</th><td>", html_escape(input.format()),
             "</td></tr>\n", "<tr><th>Voxel type</th><td>", html_escape(input.voxel_type()),
             "</td></tr>\n", "<tr><th>Grid (voxels)</th><td>", triple(input.dims(), 0),
             "</td></tr>\n", "<tr><th>Spacing (mm)</th><td>", triple(input.spacing(), 4),
             "</td></tr>\n", "<tr><th>Drawn spacing (mm)</th><td>",
             triple(input.drawn_spacing(), 4), "</td></tr>\n",
             input.meshed_spacing_size() == 3
                 ? cat("<tr><th>Meshed on (mm)</th><td>", triple(input.meshed_spacing(), 4), " (",
                       triple(input.meshed_dims(), 0),
                       " voxels: the labels were resampled from this grid)</td></tr>\n")
                 : std::string(),
             "<tr><th>Origin (mm)</th><td>", triple(input.origin(), 3), "</td></tr>\n",
             "<tr><th>Background voxels</th><td class=\"num\">", input.background_voxels(),
             "</td></tr>\n", "<tr><th>File</th><td>",
             input.file_name().empty() ? std::string(kNone) : html_escape(input.file_name()),
             "</td></tr>\n<tr><th>SHA-256</th><td><code>",
             input.sha256().empty() ? std::string(kNone) : html_escape(input.sha256()),
             "</code></td></tr>\n</table>\n");
}

std::string png_image(const std::string& png, std::string_view alt) {
  return cat("<img src=\"data:image/png;base64,", absl::Base64Escape(png), "\" alt=\"",
             html_escape(alt), "\">");
}

// Every surface from three sides, then each label alone from the front.
std::string pictures_section(const v1::Report& report, const SurfacePictures& pictures) {
  if (pictures.overview_png.empty()) return "";
  std::string html =
      cat("<h2>Surfaces</h2>\n<figure>\n",
          png_image(pictures.overview_png,
                    "every delivered surface from the front, the left and the feet"),
          "\n<figcaption>From the front (the patient's left on the right), from the patient's left "
          "(anterior on the left) and from the feet (anterior up, the patient's left on the right, "
          "as axial images are shown).</figcaption>\n</figure>\n"
          "<div class=\"labels\">\n");
  for (const auto& [label, png] : pictures.label_png) {
    const std::string name = label_name(report, label);
    html += cat("<figure class=\"label\">", png_image(png, name), "<figcaption>",
                html_escape(shorten(name, 28)), "</figcaption></figure>\n");
  }
  return html + "</div>\n";
}

std::string name_cell(const v1::LabelSummary& label) {
  const std::string colour = label_colour(label);
  std::string out = "<td>";
  if (!colour.empty())
    out += cat("<span class=\"swatch\" style=\"background:", colour, "\"></span>");
  return cat(out, html_escape(label.name()), "</td>");
}

// The label's error when its stages failed, else its warnings.
std::string notes_cell(const v1::Report& report, int32_t label, const v1::SurfaceSummary* surface) {
  if (surface && !surface->error().empty())
    return cat("<td class=\"error\">failed: ", html_escape(surface->error()), "</td>");
  std::string out = "<td class=\"warning\">";
  for (const auto& warning : report.warnings()) {
    if (warning.label() == label) out += cat(html_escape(warning.reason()), "<br>");
  }
  return out + "</td>";
}

std::string surface_cells(const v1::SurfaceSummary* s) {
  if (!s || !s->output()) {
    std::string out = cat("<td>", s ? html_escape(s->stage()) : std::string(kNone), "</td>");
    for (int i = 0; i < 7; ++i) out += cat("<td class=\"num\">", kNone, "</td>");
    return out;
  }
  const auto num = [](const std::string& text) { return cat("<td class=\"num\">", text, "</td>"); };
  return cat("<td>", html_escape(s->stage()), "</td>", num(cat(s->nodes())),
             num(cat(s->triangles())), num(fixed(s->min_angle_deg(), 2)),
             num(cat(s->triangles_below_30_deg())), num(fixed(s->max_angle_deg(), 2)),
             num(fixed(s->volume_mm3(), 1)),
             num(s->has_hausdorff_mm() ? fixed(s->hausdorff_mm(), 3) : std::string(kNone)));
}

std::string label_table(const v1::Report& report) {
  std::string out =
      "<h2>Labels</h2>\n<table>\n<tr><th>Label</th><th>Name</th><th>Voxels</th>"
      "<th>Voxel volume (mm&sup3;)</th><th>Surface</th><th>Nodes</th><th>Triangles</th>"
      "<th>Min angle (&deg;)</th><th>Triangles with an angle below 30&deg;</th>"
      "<th>Max angle (&deg;)</th><th>Surface volume (mm&sup3;)</th>"
      "<th>Hausdorff to Marching Cubes (mm)</th><th>Warnings and errors</th></tr>\n";
  for (const auto& label : report.input().labels()) {
    const auto* surface = final_surface(report, label.label());
    out += cat("<tr><td class=\"num\">", label.label(), "</td>", name_cell(label),
               "<td class=\"num\">", label.voxels(), "</td><td class=\"num\">",
               fixed(label.volume_mm3(), 1), "</td>", surface_cells(surface),
               notes_cell(report, label.label(), surface), "</tr>\n");
  }
  return out + "</table>\n";
}

// Each delivered surface's smallest to largest triangle angle.
Chart surface_angle_chart(const v1::Report& report) {
  Chart chart{
      "Surface triangle angles per label (smallest to largest)", "angle (degrees)", 180, {}};
  for (const auto& s : report.surfaces()) {
    if (!s.output() || s.triangles() == 0) continue;
    const auto* label = find_label(report, s.label());
    const std::string colour = label ? label_colour(*label) : "";
    chart.bars.push_back(
        {label_name(report, s.label()), s.min_angle_deg(), s.max_angle_deg(),
         cat(fixed(s.min_angle_deg(), 2), "\xC2\xB0 to ", fixed(s.max_angle_deg(), 2), "\xC2\xB0"),
         colour.empty() ? "#4a78b5" : colour});
  }
  return chart;
}

// Cells per category of the paper's Table 1 (tetrahedra by Q, the other
// cells of a mixed mesh by their Jacobian ratio).
Chart category_chart(const v1::QualityCategories& c, bool tetrahedra_only) {
  Chart chart{tetrahedra_only ? "Tetrahedra per quality category (Table 1)"
                              : "Cells per quality category (Table 1: Jacobian ratio, Q for "
                                "tetrahedra)",
              tetrahedra_only ? "tetrahedra" : "cells",
              1,
              {}};
  chart.bars = {
      {"invalid (Q \xE2\x89\xA4 0.001)", 0, double(c.invalid()), cat(c.invalid()), "#b00020"},
      {"very bad (\xE2\x89\xA4 1/30)", 0, double(c.very_bad()), cat(c.very_bad()), "#e06000"},
      {"questionable (\xE2\x89\xA4 0.2)", 0, double(c.questionable()), cat(c.questionable()),
       "#d8b000"},
      {"good (> 0.2)", 0, double(c.good()), cat(c.good()), "#3a8f3a"}};
  for (const auto& bar : chart.bars) chart.axis_max = std::max(chart.axis_max, bar.to);
  return chart;
}

// A table row: a name and a number.
std::string row(std::string_view name, const std::string& value) {
  return cat("<tr><th>", name, "</th><td class=\"num\">", value, "</td></tr>\n");
}

// The hexahedra, pyramids and tetrahedra of a mixed or hexahedral mesh, and
// the labels that fell back or were left out, with why.
std::string mixed_volume_section(const v1::VolumeMeshSummary& v) {
  std::string html = cat(
      "<h2>Volume mesh (", html_escape(v.mesher()), ")</h2>\n<table>\n",
      row("Cube edge (mm)", fixed(v.hex_size_mm(), 2)),
      v.hex_interior_size_mm() > 0 ? row("Largest octant (mm)", fixed(v.hex_interior_size_mm(), 2))
                                   : "",
      row("Nodes", cat(v.nodes())), row("Hexahedra", cat(v.hexahedra())),
      row("Pyramids", cat(v.pyramids())), row("Prisms", cat(v.prisms())),
      row("Tetrahedra", cat(v.tetrahedra())),
      row("Jacobian ratio, min", fixed(v.jacobian_ratio_min(), 3)),
      row("Jacobian ratio, mean", fixed(v.jacobian_ratio_mean(), 3)),
      v.has_scaled_jacobian_min() ? row("Scaled Jacobian, min", fixed(v.scaled_jacobian_min(), 3))
                                  : "",
      v.has_pyramid_aspect_ratio_min()
          ? row("Pyramid aspect ratio, min", fixed(v.pyramid_aspect_ratio_min(), 3))
          : "",
      row("Inverted cells", cat(v.inverted())),
      row("Volume against the surfaces (%)", fixed(100 * v.volume_change(), 3)),
      row("Outer nodes' distance to the surface, max (mm)",
          fixed(v.boundary_node_distance_max_mm(), 6)),
      "</table>\n");
  const auto labels = [](std::string_view title, const auto& items) {
    if (items.empty()) return std::string();
    std::string list = cat("<h3>", title, "</h3>\n<ul>\n");
    for (const auto& item : items)
      list += cat("<li>label ", item.label(), ": ", html_escape(item.reason()), "</li>\n");
    return list + "</ul>\n";
  };
  html += labels("Labels with a tetrahedral outer layer", v.tetrahedral_layer_labels());
  html += labels("Labels left out", v.labels_left_out());
  return html + svg_chart(category_chart(v.categories(), false));
}

// One tetrahedral mesh of every label: its quality, its interfaces and
// conformity check, and each label's volume against its voxels.
std::string conforming_volume_section(const v1::VolumeMeshSummary& v) {
  const auto& c = v.conforming_figures();
  const auto& check = v.conformity_check();
  std::string html = cat("<h2>Volume mesh (conforming: one mesh of every label)</h2>\n<table>\n",
                         row("Nodes", cat(v.nodes())), row("Tetrahedra", cat(v.tetrahedra())),
                         row("Quality Q, min", fixed(v.tetra_quality_min(), 3)),
                         row("Quality Q, mean", fixed(v.tetra_quality_mean(), 3)),
                         row("Dihedral angle, min (&deg;)", fixed(v.min_dihedral_deg(), 2)),
                         row("Dihedral angle, max (&deg;)", fixed(v.max_dihedral_deg(), 2)),
                         row("Inverted cells", cat(v.inverted())),
                         row("Interfaces (label pairs, the outside included)", cat(c.interfaces())),
                         row("Interface faces", cat(c.interface_faces())),
                         row("Outer faces", cat(c.outer_faces())),
                         row("Interfaces' distance to the voxel boundary, max (mm)",
                             fixed(c.interface_offset_max_mm(), 3)),
                         row("Volume gap between labels (%)", fixed(100 * c.volume_gap(), 4)),
                         row("Non-conforming faces", cat(check.nonconforming_faces())),
                         row("Duplicate points", cat(check.duplicate_points())),
                         row("Open boundary edges", cat(check.open_boundary_edges())),
                         row("Cavities left empty", cat(c.outside_regions())), "</table>\n");
  if (c.labels_size() > 0) {
    html +=
        "<h3>Labels in the mesh</h3>\n<table>\n<tr><th>Label</th><th>Voxels</th>"
        "<th>Voxel volume (mm&sup3;)</th><th>Mesh volume (mm&sup3;)</th><th>Tetrahedra</th>"
        "<th>Volume change (%)</th></tr>\n";
    for (const auto& label : c.labels()) {
      html += cat("<tr><td class=\"num\">", label.label(), "</td><td class=\"num\">",
                  label.voxels(), "</td><td class=\"num\">", fixed(label.voxel_volume_mm3(), 1),
                  "</td><td class=\"num\">", fixed(label.mesh_volume_mm3(), 1),
                  "</td><td class=\"num\">", label.tetrahedra(), "</td><td class=\"num\">",
                  fixed(100 * label.volume_change(), 2), "</td></tr>\n");
    }
    html += "</table>\n";
  }
  return html + svg_chart(category_chart(v.categories(), true));
}

std::string volume_section(const v1::VolumeMeshSummary& v) {
  if (v.mesher() == "conforming") return conforming_volume_section(v);
  if (v.mesher() != "tetgen") return mixed_volume_section(v);
  return cat("<h2>Volume mesh (", html_escape(v.mesher()), ")</h2>\n<table>\n",
             row("Nodes", cat(v.nodes())), row("Tetrahedra", cat(v.tetrahedra())),
             row("Steiner points", cat(v.steiner_points())),
             row("Quality Q, min", fixed(v.tetra_quality_min(), 3)),
             row("Quality Q, mean", fixed(v.tetra_quality_mean(), 3)),
             row("Dihedral angle, min (&deg;)", fixed(v.min_dihedral_deg(), 2)),
             row("Dihedral angle, max (&deg;)", fixed(v.max_dihedral_deg(), 2)),
             row("Conforming across labels", v.conforming() ? "yes" : "no"), "</table>\n",
             svg_chart(category_chart(v.categories(), true)));
}

}  // namespace

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string report_html(const v1::Report& report, const SurfacePictures& pictures) {
  const std::string version = html_escape(report.labelmesh_version());
  const std::string& convention = report.input().convention();
  const std::string made =
      report.created_at().empty() ? "" : cat(" on ", html_escape(report.created_at()));
  const std::string title =
      report.input().file_name().empty()
          ? std::string("labelmesh report")
          : cat("labelmesh report: ", html_escape(report.input().file_name()));
  std::string out =
      cat("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n", "<title>",
          title, "</title>\n<style>", kStyle, "</style>\n</head>\n<body>\n<h1>", title, "</h1>\n",
          "<p>Made by labelmesh ", version, made, ". Coordinates are ",
          html_escape(convention.empty() ? kPatientConvention : convention),
          " millimetres, in the input's physical space.</p>\n");
  out += input_section(report);
  out += label_table(report);
  out += pictures_section(report, pictures);
  if (const Chart angles = surface_angle_chart(report); !angles.bars.empty())
    out += cat("<h2>Surface quality</h2>\n", svg_chart(angles));
  if (report.has_volume()) out += volume_section(report.volume());
  return out + "</body>\n</html>\n";
}

}  // namespace labelmesh
