// SPDX-License-Identifier: AGPL-3.0-or-later
// Names of the files a job writes: the label number always, and a safe
// slug of the label's name when the input gives one (surface-label5-liver).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/header/label_description.h"
#include "core/util/name_slug.h"

namespace labelmesh {

// "surface-label<N>" or "surface-label<N>-<slug>".
std::string surface_file_stem(int32_t label, const volume::LabelDescriptions& descriptions);

}  // namespace labelmesh
