// SPDX-License-Identifier: AGPL-3.0-or-later
#include "server/error_details.h"

#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_join.h"
#include "google/rpc/status.pb.h"

namespace labelmesh::server {
namespace {

bool is_field_name(std::string_view text) {
  if (text.empty()) return false;
  for (char c : text) {
    const bool allowed = absl::ascii_islower(static_cast<unsigned char>(c)) ||
                         absl::ascii_isdigit(static_cast<unsigned char>(c)) || c == '_' ||
                         c == '.' || c == '[' || c == ']';
    if (!allowed) return false;
  }
  return true;
}

// "spec.options: max_edge_voxels: must be ..." ->
// {"spec.options.max_edge_voxels", "must be ..."}; empty field when the
// message does not start with a field name.
std::pair<std::string, std::string> split_field(std::string_view message) {
  std::vector<std::string> path;
  std::string_view rest = message;
  for (size_t colon; (colon = rest.find(": ")) != std::string_view::npos;) {
    if (!is_field_name(rest.substr(0, colon))) break;
    path.emplace_back(rest.substr(0, colon));
    rest = rest.substr(colon + 2);
  }
  return {absl::StrJoin(path, "."), std::string(rest)};
}

}  // namespace

grpc::Status to_grpc(const absl::Status& status) {
  const auto code = static_cast<grpc::StatusCode>(status.code());
  const std::string message(status.message());
  if (status.code() != absl::StatusCode::kInvalidArgument) return grpc::Status(code, message);
  auto [field, description] = split_field(message);
  if (field.empty()) return grpc::Status(code, message);
  google::rpc::BadRequest bad_request;
  auto* violation = bad_request.add_field_violations();
  violation->set_field(field);
  violation->set_description(description);
  google::rpc::Status details;
  details.set_code(static_cast<int>(code));
  details.set_message(message);
  details.add_details()->PackFrom(bad_request);
  return grpc::Status(code, message, details.SerializeAsString());
}

}  // namespace labelmesh::server
