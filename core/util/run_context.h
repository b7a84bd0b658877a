// SPDX-License-Identifier: AGPL-3.0-or-later
// What every pipeline stage receives besides its inputs: a way to report
// progress and a way to be asked to stop. No global state lives anywhere else.
#pragma once

#include <atomic>
#include <functional>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh {

struct RunContext {
  // Called with the stage name and the fraction of that stage done, in [0, 1].
  // May be empty. Called from the thread that runs the stage.
  std::function<void(std::string_view stage, double fraction)> progress;
  // Set by another thread to ask the run to stop; stages poll it at loop granularity.
  const std::atomic<bool>* stop = nullptr;

  bool stop_requested() const { return stop != nullptr && stop->load(std::memory_order_relaxed); }

  void report(std::string_view stage, double fraction) const {
    if (progress) progress(stage, fraction);
  }

  // CANCELLED when a stop was requested, OK otherwise.
  absl::Status check_stop() const {
    return stop_requested() ? absl::CancelledError("the run was cancelled") : absl::OkStatus();
  }
};

}  // namespace labelmesh
