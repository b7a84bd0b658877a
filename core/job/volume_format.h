// SPDX-License-Identifier: AGPL-3.0-or-later
// The volume mesh file formats by name, apart from the writers.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

namespace labelmesh::volume_mesh {

enum class VolumeFormat { kVtu, kMsh, kMedit, kAbaqus, kTetgen, kXdmf };

// "vtu", "msh", "mesh", "inp", "node" or "xdmf"; nullopt otherwise.
std::optional<VolumeFormat> volume_format_from_name(std::string_view name);
// The file extension without the dot; also the format's name.
std::string_view volume_format_name(VolumeFormat format);
const std::vector<VolumeFormat>& all_volume_formats();

}  // namespace labelmesh::volume_mesh
