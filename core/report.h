// The one translation between core types and the proto schema
// (proto/labelmesh/v1): job options in, quality report out.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/mesh_params.h"
#include "core/pipeline.h"
#include "labelmesh/v1/options.pb.h"
#include "labelmesh/v1/report.pb.h"

namespace labelmesh {

// The frame every coordinate in our output is given in.
inline constexpr std::string_view kPatientConvention = "LPS";

v1::InputSummary make_input_summary(const VolumeSummary& summary);
v1::Report make_report(const MeshResult& result, const MeshParams& params);
v1::MeshOptions make_options(const MeshParams& params);

// Errors: INVALID_ARGUMENT naming the option at fault.
absl::StatusOr<MeshParams> params_from_options(const v1::MeshOptions& options);

// Protobuf JSON with the proto field names (snake_case), every field printed.
std::string to_json(const google::protobuf::Message& message);
std::string report_json(const MeshResult& result, const MeshParams& params);

}  // namespace labelmesh
