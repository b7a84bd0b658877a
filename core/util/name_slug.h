// SPDX-License-Identifier: AGPL-3.0-or-later
// A label's name as a token safe in file names, URLs and mesh group names.
#pragma once

#include <string>
#include <string_view>

namespace labelmesh {

// Lower-case ASCII letters and digits of `name`, every other run of
// characters one '-', none at either end, at most 48 characters: safe in a
// file name on every system and in a URL. Empty when nothing is left.
std::string name_slug(std::string_view name);

}  // namespace labelmesh
