// Sequences of frame durations that drive a run: fixed rates, seeded jitter, or a recorded list.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "particles/Clock.h"

namespace tickfx::app {

/// Parses "60", "30000/1001" or "23.976"-free ratios: an integer or N/D with positive integers.
/// Throws std::invalid_argument with a message naming `text` when it is not one, or when a frame
/// at that rate is not a whole number of flicks.
FrameRate parseFrameRate(std::string_view text);

/// The frame durations of a run, made one at a time as the run needs them: a run of 10⁹ frames
/// holds none of them in memory.
class FrameSchedule {
 public:
  /// Frames of one `rate` covering exactly `total` flicks, the last one shortened to end there.
  static FrameSchedule fixedRate(FrameRate rate, Flicks total);
  /// Seeded durations in [1/240 s, 1/10 s] ending exactly at `total` (see jitteredFrames()).
  static FrameSchedule jittered(std::uint64_t seed, Flicks total);
  /// A recorded list of durations.
  static FrameSchedule recorded(std::vector<Flicks> frames);

  /// The next frame's duration, or nullopt after the last.
  std::optional<Flicks> next();
  /// Flicks the whole schedule adds up to.
  Flicks total() const { return total_; }
  /// Frames handed out so far.
  std::int64_t framesDone() const { return index_; }

 private:
  enum class Kind { Fixed, Jittered, Recorded };
  FrameSchedule(Kind kind, Flicks total) : kind_(kind), total_(total) {}

  Kind kind_;
  Flicks total_;
  Flicks elapsed_ = 0;
  std::int64_t index_ = 0;
  Flicks frame_ = 0;          // Fixed
  std::uint64_t seed_ = 0;    // Jittered
  std::vector<Flicks> list_;  // Recorded
};

/// The length of `count` frames at `rate`, in flicks. Throws std::runtime_error "WHAT: ..." when
/// it is longer than kMaxRunSeconds (io/effect/EffectSettings.h).
Flicks lengthOfFrames(FrameRate rate, std::int64_t count, const std::string& what);

/// Frames of one `rate` covering exactly `total` flicks: whole frames, then one shorter last frame
/// if `total` is not a multiple (so the run ends exactly at `total`).
std::vector<Flicks> fixedRateFrames(FrameRate rate, Flicks total);

/// A seeded sequence of frame durations uniform in [1/240 s, 1/10 s] (whole flicks), the last one
/// trimmed so that the sum is exactly `total`. A pure function of (`seed`, `total`).
std::vector<Flicks> jitteredFrames(std::uint64_t seed, Flicks total);

/// Reads one duration in seconds a line (blank lines and lines starting with '#' skipped), each
/// rounded to the nearest flick. Throws std::runtime_error naming the file and line of a bad value
/// (not a number, negative, not finite).
std::vector<Flicks> readFrameTimes(const std::filesystem::path& path);

}  // namespace tickfx::app
