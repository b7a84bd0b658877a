// SPDX-License-Identifier: AGPL-3.0-or-later
// Early returns for a step that failed: the calling function returns the
// step's status (absl::Status, an absl::StatusOr's status, or grpc::Status)
// when it is not ok.
#pragma once

#include <type_traits>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace labelmesh::status_internal {

template <typename T>
struct IsStatusOr : std::false_type {};
template <typename T>
struct IsStatusOr<absl::StatusOr<T>> : std::true_type {};

// The status inside `status`: a StatusOr's, or the status itself.
template <typename S>
const auto& status_of(const S& status) {
  if constexpr (IsStatusOr<S>::value) {
    return status.status();
  } else {
    return status;
  }
}

}  // namespace labelmesh::status_internal

// LABELMESH_RETURN_IF_ERROR(write(file)); returns write's status unless ok.
#define LABELMESH_RETURN_IF_ERROR(expr)                                 \
  do {                                                                  \
    if (const auto& labelmesh_status = (expr); !labelmesh_status.ok())  \
      return ::labelmesh::status_internal::status_of(labelmesh_status); \
  } while (false)

#define LABELMESH_STATUS_CONCAT_INNER(a, b) a##b
#define LABELMESH_STATUS_CONCAT(a, b) LABELMESH_STATUS_CONCAT_INNER(a, b)

// LABELMESH_ASSIGN_OR_RETURN(auto job, store.get(id)); declares (or assigns)
// `job` from a StatusOr's value, or returns its status unless ok.
#define LABELMESH_ASSIGN_OR_RETURN(lhs, expr) \
  LABELMESH_ASSIGN_OR_RETURN_IMPL(LABELMESH_STATUS_CONCAT(labelmesh_or_, __LINE__), lhs, expr)
#define LABELMESH_ASSIGN_OR_RETURN_IMPL(or_value, lhs, expr) \
  auto or_value = (expr);                                    \
  if (!or_value.ok()) return std::move(or_value).status();   \
  lhs = *std::move(or_value)
