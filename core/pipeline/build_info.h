// SPDX-License-Identifier: AGPL-3.0-or-later
// How this program was built, for the report.
#pragma once

#include "labelmesh/v1/report.pb.h"

namespace labelmesh {

v1::BuildInfo build_info();

}  // namespace labelmesh
