// SPDX-License-Identifier: AGPL-3.0-or-later
// Statuses as gRPC sends them: code and message, and for INVALID_ARGUMENT a
// google.rpc.BadRequest in the details that names the field at fault, taken
// from the message's leading "field: field: description" form.
#pragma once

#include <grpcpp/grpcpp.h>

#include "absl/status/status.h"

namespace labelmesh::server {

grpc::Status to_grpc(const absl::Status& status);

}  // namespace labelmesh::server
