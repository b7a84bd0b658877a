// SPDX-License-Identifier: AGPL-3.0-or-later
// Two pieces of work at once, on this thread and one more.
#pragma once

#include <cstddef>
#include <exception>
#include <thread>

namespace labelmesh {

// Runs `there` on a second thread and `here` on this one. An exception from
// either (bad_alloc, say) is rethrown once both are done, instead of ending
// the process through a joinable thread's destructor.
template <typename There, typename Here>
void side_by_side(There&& there, Here&& here) {
  std::exception_ptr there_error;
  std::thread thread([&] {
    try {
      there();
    } catch (...) {
      there_error = std::current_exception();
    }
  });
  try {
    here();
  } catch (...) {
    thread.join();
    throw;
  }
  thread.join();
  if (there_error) std::rethrow_exception(there_error);
}

// Runs work(begin, end) over [0, count) in two halves side by side; the
// halves must write apart.
template <typename Work>
void in_two_halves(size_t count, Work&& work) {
  side_by_side([&] { work(count / 2, count); }, [&] { work(size_t{0}, count / 2); });
}

}  // namespace labelmesh
