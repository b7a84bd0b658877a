// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/volume_mesh/tetgen_call.h"

#include <charconv>
#include <cmath>
#include <exception>
#include <new>

#include "core/util/text.h"

namespace labelmesh::volume_mesh {
namespace {

// A number as TetGen's switch parser reads it: plain decimal, no exponent.
std::string switch_number(double value) {
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  return std::string(buffer, result.ptr);
}

absl::Status tetgen_error(int code, std::string_view what) {
  switch (code) {
    case 1:
      return absl::ResourceExhaustedError(cat("tetgen: ran out of memory meshing ", what));
    case 2:
      return absl::InternalError(cat("tetgen: internal error while meshing ", what));
    case 3:
      return absl::FailedPreconditionError(cat("tetgen: ", what, " intersects itself"));
    case 4:
      return absl::FailedPreconditionError(
          cat("tetgen: ", what, " has a feature below TetGen's tolerance (1e-8 of its size)"));
    case 5:
      return absl::FailedPreconditionError(
          cat("tetgen: ", what, " has two facets that nearly coincide"));
    case 10:
      return absl::FailedPreconditionError(cat("tetgen: rejected ", what, " as invalid input"));
    default:
      return absl::InternalError(cat("tetgen: failed with code ", code, " meshing ", what));
  }
}

}  // namespace

absl::Status run_tetgen(const std::string& switches, tetgenio& in, tetgenio& out,
                        std::string_view what) {
  try {
    tetgenbehavior behavior;
    std::string buffer = switches;
    if (!behavior.parse_commandline(buffer.data())) {
      return absl::InternalError(cat("tetgen: rejected the switches '", switches, "'"));
    }
    ::tetrahedralize(&behavior, &in, &out);
  } catch (int code) {
    return tetgen_error(code, what);
  } catch (const std::bad_alloc&) {
    return tetgen_error(1, what);
  } catch (const std::exception& e) {
    return absl::InternalError(cat("tetgen: ", e.what(), " while meshing ", what));
  } catch (...) {
    return absl::InternalError(cat("tetgen: unknown failure meshing ", what));
  }
  return absl::OkStatus();
}

void fill_triangle_plc(const std::vector<std::array<double, 3>>& points,
                       const std::vector<std::array<uint32_t, 3>>& triangles, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(points.size());
  in.pointlist = new REAL[3 * points.size()];
  for (size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = points[i][k];
  }
  // Value-initialised, so that tetgenio's destructor finds null lists if an allocation fails.
  in.facetlist = new tetgenio::facet[triangles.size()]();
  in.numberoffacets = static_cast<int>(triangles.size());
  in.facetmarkerlist = new int[triangles.size()];
  for (size_t i = 0; i < triangles.size(); ++i) {
    tetgenio::facet& facet = in.facetlist[i];
    facet.polygonlist = new tetgenio::polygon[1]();
    facet.numberofpolygons = 1;
    tetgenio::polygon& polygon = facet.polygonlist[0];
    polygon.vertexlist = new int[3];
    polygon.numberofvertices = 3;
    for (int k = 0; k < 3; ++k) polygon.vertexlist[k] = static_cast<int>(triangles[i][k]);
    in.facetmarkerlist[i] = static_cast<int>(i) + 1;
  }
}

std::array<double, 3> tetgen_point(const tetgenio& out, int index) {
  const REAL* p = out.pointlist + 3 * static_cast<size_t>(index);
  return {p[0], p[1], p[2]};
}

std::string tetgen_quality_switches(const TetgenParams& params) {
  std::string switches = cat("pq", switch_number(params.radius_edge_ratio), "/",
                             switch_number(params.min_dihedral_deg));
  if (params.max_volume_mm3 > 0) switches += cat("a", switch_number(params.max_volume_mm3));
  if (params.keep_boundary) switches += "Y";
  return switches + cat("o/", switch_number(params.max_dihedral_deg));
}

}  // namespace labelmesh::volume_mesh
