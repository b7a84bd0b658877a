// SPDX-License-Identifier: AGPL-3.0-or-later
// Wavefront OBJ written here rather than by VTK's writer, which has no place
// for comments or groups: the frame and the label go in both.
#include "core/surface/write_surface.h"
#include "core/util/name_slug.h"
#include "core/util/text_file.h"

namespace labelmesh::surface {

absl::Status write_obj(const TriangleMesh& mesh, const std::string& path,
                       const SurfaceFileInfo& info) {
  TextFile file(path, "the surface");
  file << "# SPACE=" << frame_name(info.frame) << "\n# labelmesh label " << info.label;
  if (!info.name.empty()) file << ' ' << info.name;
  file << '\n';
  std::string group = cat("label", info.label);
  if (const std::string slug = name_slug(info.name); !slug.empty()) group += cat("-", slug);
  file << "o " << group << "\ng " << group << '\n';
  for (const auto& lps : mesh.points) {
    const auto p = in_frame(lps, info.frame);
    file << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  }
  for (const auto& t : mesh.triangles)
    file << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  return file.finish();
}

}  // namespace labelmesh::surface
