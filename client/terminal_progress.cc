// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/terminal_progress.h"

#include <unistd.h>

#include <algorithm>

#include "core/util/text.h"
#include "core/util/utf8.h"

namespace labelmesh::client {
namespace {

// Wide enough for a long organ name, narrow enough for a default terminal.
constexpr size_t kLineWidth = 100;

}  // namespace

std::string progress_text(const ProgressLine& line) {
  const int percent = std::clamp(static_cast<int>(line.fraction * 100), 0, 100);
  std::string text = cat(line.stage, " ", percent, " %");
  if (line.label == 0) return text;
  std::string label = cat("label ", line.label);
  if (!line.label_name.empty()) label += cat(" ", line.label_name);
  return cat(label, " (", line.label_index, "/", line.label_count, ") ", text, ", ",
             line.labels_done, "/", line.label_count, " labels done");
}

TerminalProgress::TerminalProgress(bool enabled, bool print_stage_ends)
    : active_(enabled && isatty(STDERR_FILENO) == 1), print_stage_ends_(print_stage_ends) {}

TerminalProgress::~TerminalProgress() { clear(); }

void TerminalProgress::end_stage() {
  if (stage_.empty()) return;
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - stage_start_;
  std::fprintf(stderr, "\r\033[K");
  if (print_stage_ends_)
    std::fprintf(stderr, "  %-20s done  %7.2f s\n", stage_.c_str(), took.count());
  stage_.clear();
  last_text_.clear();
}

void TerminalProgress::clear() {
  if (!active_) return;
  end_stage();
  std::fflush(stderr);
}

void TerminalProgress::update(const ProgressLine& line) {
  if (!active_) return;
  // Labels are meshed several at a time and their stages interleave: they
  // share one "labels" stage, so only whole-volume stages end a line.
  const std::string stage = line.label == 0 ? line.stage : "labels";
  if (stage != stage_) {
    end_stage();
    stage_ = stage;
    stage_start_ = std::chrono::steady_clock::now();
  }
  std::string text = progress_text(line);
  text = std::string(utf8_prefix(text, kLineWidth));
  if (text == last_text_) return;
  last_text_ = text;
  // Carriage return and erase to the end of the line: a shorter line leaves no tail.
  std::fprintf(stderr, "\r\033[K  %s", text.c_str());
  std::fflush(stderr);
}

}  // namespace labelmesh::client
