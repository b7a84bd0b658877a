// SPDX-License-Identifier: AGPL-3.0-or-later
// The quality report: core results in the proto schema
// (proto/labelmesh/v1/report.proto), and as JSON.
#pragma once

#include <string>
#include <string_view>

#include "core/job/mesh_params.h"
#include "core/pipeline/mesh_result.h"
#include "labelmesh/v1/report.pb.h"

namespace labelmesh {

// The frame every coordinate in our output is given in.
inline constexpr std::string_view kPatientConvention = "LPS";

v1::InputSummary make_input_summary(const VolumeSummary& summary);
v1::Report make_report(const MeshResult& result, const MeshParams& params);

// Protobuf JSON with the proto field names (snake_case), every field printed.
std::string to_json(const google::protobuf::Message& message);

}  // namespace labelmesh
