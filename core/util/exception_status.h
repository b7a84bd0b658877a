// SPDX-License-Identifier: AGPL-3.0-or-later
// The status of the exception being handled, for the catch (...) at the edge
// of a function that calls into CGAL or another library that throws: no
// exception crosses a public function of the core library.
#pragma once

#include <exception>
#include <new>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "core/util/text.h"

namespace labelmesh {

// RESOURCE_EXHAUSTED for std::bad_alloc, INTERNAL with what() for any other
// std::exception, INTERNAL for anything else; `where` names the stage. Only
// to be called inside a catch block.
inline absl::Status current_exception_status(std::string_view where) {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(cat(where, ": out of memory"));
  } catch (const std::exception& e) {
    return absl::InternalError(cat(where, ": ", e.what()));
  } catch (...) {
    return absl::InternalError(cat(where, ": an unknown exception"));
  }
}

}  // namespace labelmesh
