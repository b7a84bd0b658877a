// SPDX-License-Identifier: AGPL-3.0-or-later
// The surface file formats by name, apart from the writers (which need VTK).
#pragma once

#include <optional>
#include <string_view>
#include <vector>

namespace labelmesh::surface {

enum class SurfaceFormat { kStl, kPly, kObj, kOff, kVtp };

// "stl", "ply", "obj", "off" or "vtp"; nullopt otherwise.
std::optional<SurfaceFormat> surface_format_from_name(std::string_view name);
// The file extension without the dot; also the format's name.
std::string_view surface_format_name(SurfaceFormat format);
const std::vector<SurfaceFormat>& all_surface_formats();

}  // namespace labelmesh::surface
