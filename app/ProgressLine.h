// A one-line progress report for people watching a terminal.
#pragma once

#include <chrono>
#include <cstdint>

namespace tickfx::app {

/// Rewrites one line on stderr, at most ten times a second, and only when stderr is a terminal
/// and the run has lasted more than a second (short runs and logs stay clean).
class ProgressLine {
 public:
  ProgressLine();
  ~ProgressLine();
  void update(std::int64_t frame, double simSeconds, double totalSeconds, std::size_t particles);
  /// Erases the line.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_;
  Clock::time_point last_;
};

}  // namespace tickfx::app
