// SPDX-License-Identifier: AGPL-3.0-or-later
// The summary people read after a run: one row per label with its name and
// the figures of its delivered surface, then the volume mesh's figures.
#pragma once

#include <cstdio>
#include <string>

#include "labelmesh/v1/report.pb.h"

namespace labelmesh::client {

// The table as text; every row ends in a newline.
std::string report_table(const v1::Report& report);

}  // namespace labelmesh::client
