// A progress bar on stderr for drape-replay: drawn only when stderr is a terminal, not --quiet, and
// the run has lasted more than a second; redrawn at most 10 times a second and erased at the end.
#pragma once

#include <chrono>
#include <cstdint>

namespace replay {

class ProgressBar {
 public:
  ProgressBar(uint32_t total, bool enabled);
  ~ProgressBar();
  void update(uint32_t done);  // frames done so far
  void finish();               // erases the bar (if drawn)

 private:
  using Clock = std::chrono::steady_clock;
  uint32_t total_;
  bool enabled_;
  bool drawn_ = false;
  Clock::time_point start_, last_draw_;
};

// True when stderr is a terminal.
bool stderrIsTerminal();

}  // namespace replay
