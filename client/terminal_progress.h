// SPDX-License-Identifier: AGPL-3.0-or-later
// One progress line per stage on a terminal; silent when stderr is not one.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace labelmesh::client {

class TerminalProgress {
 public:
  // Prints only when `enabled` and stderr is a terminal.
  explicit TerminalProgress(bool enabled);
  ~TerminalProgress();

  // RunContext::progress callback.
  void update(std::string_view stage, double fraction);

 private:
  void finish_line();

  bool active_;
  std::string stage_;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point stage_start_;
};

}  // namespace labelmesh::client
