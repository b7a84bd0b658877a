// SPDX-License-Identifier: AGPL-3.0-or-later
// Files written once per job beside the per-label surfaces: every surface in
// one multiblock file, and the label volume itself in the meshes' frame, so a
// viewer shows the image and the meshes aligned.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

namespace labelmesh {

enum class SceneFormat {
  kVtm,  // surfaces.vtm: one block per label
  kVti,  // labels.vti: the label volume, placed in the output frame
  kMha,  // labels.mha: the label volume, MetaImage (always LPS, as ITK reads it)
};

// "vtm", "vti" or "mha"; nullopt otherwise.
std::optional<SceneFormat> scene_format_from_name(std::string_view name);
std::string_view scene_format_name(SceneFormat format);
// The file a scene format writes: "surfaces.vtm", "labels.vti", "labels.mha".
std::string_view scene_file_name(SceneFormat format);

}  // namespace labelmesh
