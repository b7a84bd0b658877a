// SPDX-License-Identifier: AGPL-3.0-or-later
// XDMF 3 (xdmf.org, "XDMF Model and Format") with the heavy data inline as
// XML text: one file, no HDF5, read by meshio, ParaView and dolfinx.
#include <string_view>

#include "core/util/status_macros.h"
#include "core/util/text_file.h"
#include "core/volume_mesh/mesh_file_parts.h"

namespace labelmesh::volume_mesh {
namespace {

// A DataItem of `rows` x `columns` values written by `write_row(i)`.
template <typename WriteRow>
void data_item(TextFile& file, size_t rows, int columns, std::string_view number_type,
               int precision, WriteRow&& write_row) {
  file << "        <DataItem Dimensions=\"" << rows << ' ' << columns << "\" NumberType=\""
       << number_type << "\" Precision=\"" << precision << "\" Format=\"XML\">\n";
  for (size_t i = 0; i < rows; ++i) {
    write_row(i);
    file << '\n';
  }
  file << "        </DataItem>\n";
}

void geometry(TextFile& file, const TetMesh& mesh, const VolumeFileInfo& info) {
  file << "      <Geometry GeometryType=\"XYZ\">\n";
  data_item(file, mesh.points.size(), 3, "Float", 8, [&](size_t i) {
    const auto p = in_frame(mesh.points[i], info.frame);
    file << p[0] << ' ' << p[1] << ' ' << p[2];
  });
  file << "      </Geometry>\n";
}

template <typename Value>
void cell_attribute(TextFile& file, std::string_view name, size_t cells, Value&& value) {
  using T = decltype(value(size_t{0}));
  const bool real = std::is_floating_point_v<T>;
  file << "      <Attribute Name=\"" << name << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n";
  data_item(file, cells, 1, real ? "Float" : "Int", real ? 8 : 4,
            [&](size_t i) { file << value(i); });
  file << "      </Attribute>\n";
}

// The file's start. Names go into comments: meshio reads only a domain
// holding exactly one grid.
void head(TextFile& file, const VolumeFileInfo& info) {
  file << "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n";
  file << "  <!-- labelmesh: coordinates in mm, SPACE="
       << (info.frame == CoordinateFrame::kLps ? "LPS" : "RAS") << " -->\n";
}

absl::Status write_facets(const TetMesh& mesh, const VolumeFileInfo& info,
                          const std::string& path) {
  const Interfaces interfaces(*info.interfaces);
  TextFile file(path, "the volume mesh's facets");
  head(file, info);
  for (size_t i = 0; i < interfaces.pairs.size(); ++i) {
    file << "  <!-- interface " << i + 1 << ": " << interface_group_name(interfaces.pairs[i], info)
         << " -->\n";
  }
  const size_t faces = interfaces.faces.size();
  file << "  <Domain>\n    <Grid Name=\"facets\" GridType=\"Uniform\">\n";
  file << "      <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << faces
       << "\" NodesPerElement=\"3\">\n";
  data_item(file, faces, 3, "Int", 4, [&](size_t f) {
    const auto& p = interfaces.faces[f].points;
    file << p[0] << ' ' << p[1] << ' ' << p[2];
  });
  file << "      </Topology>\n";
  geometry(file, mesh, info);
  cell_attribute(file, "interface", faces,
                 [&](size_t f) { return static_cast<int32_t>(interfaces.index[f] + 1); });
  cell_attribute(file, "label_inside", faces,
                 [&](size_t f) { return interfaces.faces[f].labels[0]; });
  cell_attribute(file, "label_outside", faces,
                 [&](size_t f) { return interfaces.faces[f].labels[1]; });
  file << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return file.finish();
}

}  // namespace

absl::Status write_xdmf(const TetMesh& mesh, const std::vector<double>& quality,
                        const VolumeFileInfo& info, const std::string& path) {
  if (info.interfaces != nullptr) {
    LABELMESH_RETURN_IF_ERROR(write_facets(mesh, info, facets_xdmf_path(path)));
  }
  TextFile file(path, "the volume mesh");
  head(file, info);
  for (int32_t label : distinct_labels(mesh.labels)) {
    file << "  <!-- label " << label << ": " << label_group_name(label, info) << " -->\n";
  }
  const size_t cells = mesh.tetrahedra.size();
  file << "  <Domain>\n    <Grid Name=\"mesh\" GridType=\"Uniform\">\n";
  file << "      <Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"" << cells
       << "\" NodesPerElement=\"4\">\n";
  data_item(file, cells, 4, "Int", 4, [&](size_t t) {
    const auto& v = mesh.tetrahedra[t];
    file << v[0] << ' ' << v[1] << ' ' << v[2] << ' ' << v[3];
  });
  file << "      </Topology>\n";
  geometry(file, mesh, info);
  cell_attribute(file, "label", cells, [&](size_t t) { return mesh.labels[t]; });
  if (!quality.empty())
    cell_attribute(file, "quality", cells, [&](size_t t) { return quality[t]; });
  file << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return file.finish();
}

}  // namespace labelmesh::volume_mesh
