// SPDX-License-Identifier: AGPL-3.0-or-later
// Wall-clock time per named stage; repeated stages (one per label) add up.
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace labelmesh {

struct StageTiming {
  std::string name;
  double seconds = 0;
};

// Adds `seconds` to the stage called `name`, appending it on first use.
inline void add_stage_time(std::vector<StageTiming>& stages, const std::string& name,
                           double seconds) {
  for (auto& stage : stages) {
    if (stage.name == name) {
      stage.seconds += seconds;
      return;
    }
  }
  stages.push_back({name, seconds});
}

// Seconds from `start` until now.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Times a scope and adds it to `stages`.
class StageTimer {
 public:
  StageTimer(std::vector<StageTiming>& stages, std::string name)
      : stages_(stages), name_(std::move(name)), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() {
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start_;
    add_stage_time(stages_, name_, elapsed.count());
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  std::vector<StageTiming>& stages_;
  std::string name_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace labelmesh
