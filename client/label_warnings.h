// SPDX-License-Identifier: AGPL-3.0-or-later
// The labels a run delivered outside tolerance, not at all, or into another
// label's surface, printed on stderr so they are seen even when stdout goes
// to a file or a pipe.
#pragma once

#include <string_view>

#include "labelmesh/v1/report.pb.h"

namespace labelmesh::client {

// Nothing when the report has no warnings. Also says which labels touch in
// a volume mesh made label by label (their meshes overlap there).
void print_label_warnings(std::string_view command, const v1::Report& report);

}  // namespace labelmesh::client
