// A one-line progress bar for people watching a terminal.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace tickfx::app {

/// Rewrites one line on stderr, at most ten times a second, and only when stderr is a terminal
/// and the work has lasted more than a second (short commands and logs stay clean):
/// `[=========>              ] 120/480 frames  48.2 frames/s  7.5 s left  t = 1.000 of 4.000 s`.
class ProgressLine {
 public:
  /// `unit`: what is counted ("frames", "schedules").
  explicit ProgressLine(std::string unit);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// `done` units of `total` (0 or less: not known ahead, as for jittered frames), `fraction`
  /// of the work done in [0, 1] (the bar and the time left: units may differ in length), and a
  /// `detail` to end the line with.
  void update(std::int64_t done, std::int64_t total, double fraction, std::string_view detail);
  /// update() with units of equal length: the fraction done is done / total (total > 0).
  void update(std::int64_t done, std::int64_t total, std::string_view detail) {
    update(done, total, static_cast<double>(done) / static_cast<double>(total), detail);
  }
  /// Erases the line (before other output, and at the end); the next update() draws it again.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string unit_;
  bool enabled_;
  bool shown_ = false;
  Clock::time_point start_;
  Clock::time_point last_;
};

/// The text of one update, without the escape codes: the bar (24 wide), the count, the rate of
/// units a second over `elapsedSeconds`, the time left at that pace, and `detail`.
std::string progressText(std::int64_t done, std::int64_t total, double fraction,
                         double elapsedSeconds, std::string_view unit, std::string_view detail);

}  // namespace tickfx::app
