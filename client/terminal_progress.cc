// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/terminal_progress.h"

#include <unistd.h>

namespace labelmesh::client {

TerminalProgress::TerminalProgress(bool enabled) : active_(enabled && isatty(STDERR_FILENO) == 1) {}

TerminalProgress::~TerminalProgress() { finish_line(); }

void TerminalProgress::finish_line() {
  if (!active_ || stage_.empty()) return;
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - stage_start_;
  std::fprintf(stderr, "\r  %-20s done  %7.2f s\n", stage_.c_str(), took.count());
  stage_.clear();
}

void TerminalProgress::update(std::string_view stage, double fraction) {
  if (!active_) return;
  if (stage != stage_) {
    finish_line();
    stage_ = std::string(stage);
    stage_start_ = std::chrono::steady_clock::now();
    last_percent_ = -1;
  }
  const int percent = static_cast<int>(fraction * 100);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  std::fprintf(stderr, "\r  %-20s %3d %%", stage_.c_str(), percent);
  std::fflush(stderr);
}

}  // namespace labelmesh::client
