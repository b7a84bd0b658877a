// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/report_table.h"

#include <map>

#include "core/util/text.h"
#include "core/util/utf8.h"

namespace labelmesh::client {
namespace {

// Names longer than this are cut (at a whole character) to keep rows aligned.
constexpr size_t kNameWidth = 24;

std::string row(const char* format, auto... values) {
  char text[512];
  std::snprintf(text, sizeof text, format, values...);
  return text;
}

// Pads `name` to kNameWidth characters (not bytes: names may be UTF-8).
std::string name_cell(const std::string& name) {
  std::string cell(utf8_prefix(name, kNameWidth));
  size_t characters = 0;
  for (unsigned char c : cell) characters += (c & 0xC0) != 0x80;
  cell.append(kNameWidth > characters ? kNameWidth - characters : 0, ' ');
  return cell;
}

}  // namespace

std::string report_table(const v1::Report& report) {
  std::map<int32_t, std::string> names;
  for (const auto& label : report.input().labels()) names[label.label()] = label.name();
  std::map<int32_t, std::string> warnings;
  for (const auto& warning : report.warnings()) warnings[warning.label()] = warning.reason();

  std::string table = row("%7s  %s %-12s %8s %8s %8s %8s %14s %10s  %s\n", "label",
                          name_cell("name").c_str(), "surface", "nodes", "min_ang", "tri<30",
                          "max_ang", "volume (mm3)", "hausdorff", "warning");
  for (const auto& s : report.surfaces()) {
    if (!s.output() && s.error().empty()) continue;
    const std::string name = name_cell(names[s.label()]);
    if (!s.error().empty()) {
      table += row("%7d  %s %-12s not delivered: %s\n", s.label(), name.c_str(), s.stage().c_str(),
                   s.error().c_str());
      continue;
    }
    const std::string hausdorff = s.has_hausdorff_mm() ? format_fixed(s.hausdorff_mm(), 3) : "-";
    table += row("%7d  %s %-12s %8u %8.2f %8u %8.2f %14.1f %10s  %s\n", s.label(), name.c_str(),
                 s.stage().c_str(), s.nodes(), s.min_angle_deg(), s.triangles_below_30_deg(),
                 s.max_angle_deg(), s.volume_mm3(), hausdorff.c_str(), warnings[s.label()].c_str());
  }
  const bool tetrahedra_only = report.has_volume() && (report.volume().mesher() == "tetgen" ||
                                                       report.volume().mesher() == "conforming");
  if (report.has_volume() && !tetrahedra_only) {
    const auto& v = report.volume();
    table +=
        row("volume (%s, %.2f mm): %llu nodes, %llu hexahedra, %llu pyramids, %llu tetrahedra; "
            "Jacobian ratio min %.3f mean %.3f; tetra Q min %.3f; inverted %llu; volume %+.4f %%\n",
            v.mesher().c_str(), v.hex_size_mm(), (unsigned long long)v.nodes(),
            (unsigned long long)v.hexahedra(), (unsigned long long)v.pyramids(),
            (unsigned long long)v.tetrahedra(), v.jacobian_ratio_min(), v.jacobian_ratio_mean(),
            v.tetra_quality_min(), (unsigned long long)v.inverted(), 100 * v.volume_change());
  } else if (report.has_volume()) {
    const auto& v = report.volume();
    const auto& c = v.categories();
    table +=
        row("volume (%s): %llu nodes, %llu tetrahedra; quality Q min %.3f mean %.3f; dihedral "
            "%.1f-%.1f deg; invalid %llu, very bad %llu, questionable %llu, good %llu\n",
            v.mesher().c_str(), (unsigned long long)v.nodes(), (unsigned long long)v.tetrahedra(),
            v.tetra_quality_min(), v.tetra_quality_mean(), v.min_dihedral_deg(),
            v.max_dihedral_deg(), (unsigned long long)c.invalid(), (unsigned long long)c.very_bad(),
            (unsigned long long)c.questionable(), (unsigned long long)c.good());
  }
  if (report.has_volume() && report.volume().has_conforming_figures()) {
    const auto& f = report.volume().conforming_figures();
    table += row(
        "conforming: %llu interfaces (%llu shared faces, %llu outer); interfaces within %.2f mm "
        "of the voxel boundary; volume gap %.1e; label volume change median %.2f %%, p90 %.2f %%\n",
        (unsigned long long)f.interfaces(), (unsigned long long)f.interface_faces(),
        (unsigned long long)f.outer_faces(), f.interface_offset_max_mm(), f.volume_gap(),
        100 * f.volume_change_median(), 100 * f.volume_change_p90());
    if (f.coarsening_factors_size() == 3 &&
        f.coarsening_factors(0) * f.coarsening_factors(1) * f.coarsening_factors(2) > 1) {
      table +=
          row("conforming: %llu voxel faces between labels; resampled to %.2f x %.2f x %.2f the "
              "spacing (--conforming-max-faces)\n",
              (unsigned long long)f.interface_voxel_faces(), f.coarsening_factors(0),
              f.coarsening_factors(1), f.coarsening_factors(2));
    }
    if (f.thick_slice_axis() >= 0 && f.thick_slice_parts() > 1) {
      table += row("conforming: thick slices along voxel axis %d cut into %u each\n",
                   f.thick_slice_axis(), f.thick_slice_parts());
    }
  }
  return table;
}

}  // namespace labelmesh::client
