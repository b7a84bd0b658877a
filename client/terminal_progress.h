// SPDX-License-Identifier: AGPL-3.0-or-later
// One live progress line on a terminal, rewritten in place: the stage, and
// for stages that work label by label the label, its name and its place
// ("label 5 liver (12/61) poisson 40 %"). Silent when stderr is not a terminal.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace labelmesh::client {

// What one progress report says, from the pipeline or from a job event.
struct ProgressLine {
  std::string stage;
  double fraction = 0;
  // 0 for stages that work on the whole volume.
  int32_t label = 0;
  std::string label_name;
  uint32_t label_index = 0;
  uint32_t label_count = 0;
  uint32_t labels_done = 0;
};

// The line's text: "poisson 40 %" or "label 5 liver (12/61) poisson 40 %,
// 11/61 labels done".
std::string progress_text(const ProgressLine& line);

class TerminalProgress {
 public:
  // Prints only when `enabled` and stderr is a terminal. With
  // `print_stage_ends`, a line "<stage> done <seconds>" stays behind when a
  // whole-volume stage, or the label-by-label stages together, end.
  TerminalProgress(bool enabled, bool print_stage_ends);
  ~TerminalProgress();

  void update(const ProgressLine& line);
  // Ends the current stage and leaves the line empty.
  void clear();

 private:
  void end_stage();

  bool active_;
  bool print_stage_ends_;
  // The stage a "done" line would name: a whole-volume stage, or "labels".
  std::string stage_;
  std::string last_text_;
  std::chrono::steady_clock::time_point stage_start_;
};

}  // namespace labelmesh::client
