// SPDX-License-Identifier: AGPL-3.0-or-later
// What every pipeline stage receives besides its inputs: a way to report
// progress and a way to be asked to stop. No global state lives anywhere else.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace labelmesh {

// The label a stage is working on, for stages that work label by label.
struct LabelInProgress {
  int32_t label = 0;
  std::string name;
  // 1-based position among the labels of the run, and their number.
  uint32_t index = 0;
  uint32_t count = 0;
  // Labels whose stages have all ended.
  uint32_t done = 0;
};

struct ProgressUpdate {
  std::string_view stage;
  // Of the stage (for the label, when there is one), in [0, 1].
  double fraction = 0;
  // Null for stages that work on the whole volume.
  const LabelInProgress* label = nullptr;
};

struct RunContext {
  // Called for each report. May be empty. Called from the thread that runs
  // the stage.
  std::function<void(const ProgressUpdate&)> progress;
  // Set by another thread to ask the run to stop; stages poll it at loop granularity.
  const std::atomic<bool>* stop = nullptr;
  // The label this context's stages work on, if any.
  const LabelInProgress* label = nullptr;

  bool stop_requested() const { return stop != nullptr && stop->load(std::memory_order_relaxed); }

  void report(std::string_view stage, double fraction) const {
    if (progress) progress({stage, fraction, label});
  }

  // CANCELLED when a stop was requested, OK otherwise.
  absl::Status check_stop() const {
    return stop_requested() ? absl::CancelledError("the run was cancelled") : absl::OkStatus();
  }
};

}  // namespace labelmesh
