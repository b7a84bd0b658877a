// SPDX-License-Identifier: AGPL-3.0-or-later
// JSON string literals for the server's line-oriented logs.
#pragma once

#include <string>
#include <string_view>

namespace labelmesh::server {

// `text` as a JSON string, quotes included; control characters and bytes
// outside printable ASCII are escaped as \u00XX, byte by byte.
std::string json_string(std::string_view text);

}  // namespace labelmesh::server
