// SPDX-License-Identifier: AGPL-3.0-or-later
// OFF output through CGAL's polygon-soup writer. The only CGAL translation
// unit of the surface writers, so CGAL's compile cost stays here.
#include <CGAL/IO/OFF.h>
#include <CGAL/Simple_cartesian.h>

#include <fstream>

#include "core/surface/write_surface.h"
#include "core/util/exception_status.h"
#include "core/util/text.h"

namespace labelmesh::surface {

absl::Status write_off(const TriangleMesh& mesh, const std::string& path) {
  using Point = CGAL::Simple_cartesian<double>::Point_3;
  std::vector<Point> points;
  points.reserve(mesh.points.size());
  for (const auto& p : mesh.points) points.emplace_back(p[0], p[1], p[2]);
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  std::ofstream out(path);
  // 17 significant digits: doubles survive the round trip exactly.
  out.precision(17);
  bool written = false;
  try {
    written = out && CGAL::IO::write_OFF(out, points, polygons);
  } catch (...) {
    return current_exception_status(path);
  }
  if (!written) return absl::InternalError(cat(path, ": could not write the surface"));
  return absl::OkStatus();
}

}  // namespace labelmesh::surface
