// SPDX-License-Identifier: AGPL-3.0-or-later
// Names of the files a job writes: the label number always, and a safe
// slug of the label's name when the input gives one (surface-label5-liver).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/volume/label_description.h"

namespace labelmesh {

// Lower-case ASCII letters and digits of `name`, every other run of
// characters one '-', none at either end, at most 48 characters: safe in a
// file name on every system and in a URL. Empty when nothing is left.
std::string name_slug(std::string_view name);

// "surface-label<N>" or "surface-label<N>-<slug>".
std::string surface_file_stem(int32_t label, const volume::LabelDescriptions& descriptions);

}  // namespace labelmesh
