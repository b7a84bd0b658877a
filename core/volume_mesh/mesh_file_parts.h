// SPDX-License-Identifier: AGPL-3.0-or-later
// The pieces every volume mesh writer shares, tetrahedral and mixed: which
// labels are present, positive labels where a format needs them, the VTU's
// field data and writer, and the start of an MSH file.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/volume_mesh/write_volume_mesh.h"

#include <array>

#include "core/util/text_file.h"

class vtkFieldData;
class vtkUnstructuredGrid;

namespace labelmesh::volume_mesh {

// A conforming mesh's interface faces, each with its interface's index
// (0-based, in label-pair order).
struct Interfaces {
  const std::vector<InterfaceFace>& faces;
  std::vector<std::array<int32_t, 2>> pairs;
  std::vector<size_t> index;  // per face: its pair's index in `pairs`

  explicit Interfaces(const std::vector<InterfaceFace>& all)
      : faces(all), pairs(interface_pairs(all)) {
    index.reserve(faces.size());
    for (size_t f = 0, i = 0; f < faces.size(); ++f) {
      while (pairs[i] != faces[f].labels) ++i;
      index.push_back(i);
    }
  }
};

// `path` with `suffix` (when it ends so) replaced by `replacement`.
std::string beside(const std::string& path, std::string_view suffix, std::string_view replacement);

// XDMF 3 with inline XML data (see write_volume_mesh).
absl::Status write_xdmf(const TetMesh& mesh, const std::vector<double>& quality,
                        const VolumeFileInfo& info, const std::string& path);

// The labels in `labels`, ascending, each once.
std::vector<int32_t> distinct_labels(const std::vector<int32_t>& labels);

// INVALID_ARGUMENT naming `path` and `format` when a label is not above 0.
absl::Status check_positive_labels(const std::vector<int32_t>& labels, const std::string& path,
                                   std::string_view format);

// ASCII letters in upper case (Abaqus set names).
std::string upper_case(std::string text);

// The labels present and the frame as numeric field data, which meshio reads
// too (it refuses string arrays): one array per label, named by
// label_group_name and holding the label, and "SPACE=LPS" (or RAS) holding 1.
void add_label_fields(const std::vector<int32_t>& labels, const VolumeFileInfo& info,
                      vtkFieldData* fields);

// Writes `grid` as VTK XML (appended, zlib). INTERNAL naming `path` when it
// cannot be written.
absl::Status write_vtu_grid(vtkUnstructuredGrid* grid, const std::string& path);

// The start of a Gmsh MSH 2.2 ASCII file up to its elements: the format, a
// 3D physical group per label (tag = label, named by label_group_name), a
// 2D physical group per surface name (tag = its position + 1) and the nodes
// (numbered from 1, in info.frame). Labels must be positive.
void write_msh_head(TextFile& file, const std::vector<int32_t>& labels,
                    const std::vector<std::array<double, 3>>& points, const VolumeFileInfo& info,
                    const std::vector<std::string>& surface_names = {});

// The start of a Medit .mesh file up to its elements: version, dimension,
// comments naming the frame and each label's ref, and the vertices (ref 0,
// in info.frame).
void write_medit_head(TextFile& file, const std::vector<int32_t>& labels,
                      const std::vector<std::array<double, 3>>& points, const VolumeFileInfo& info);

// The start of an Abaqus/CalculiX .inp file up to its elements: a comment
// naming the frame and what the mesh holds, the heading, and the nodes
// (numbered from 1, in info.frame).
void write_abaqus_head(TextFile& file, std::string_view what,
                       const std::vector<std::array<double, 3>>& points,
                       const VolumeFileInfo& info);

// Abaqus/CalculiX data lines of ids: at most 16 to a line.
void write_id_lines(TextFile& file, const std::vector<size_t>& ids);

}  // namespace labelmesh::volume_mesh
