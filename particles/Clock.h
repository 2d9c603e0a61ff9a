// Exact integer time for the fixed-step driver.
#pragma once

#include <cstdint>
#include <stdexcept>

namespace tickfx {

/// Time in flicks: 1 flick = 1/705600000 s. Every common frame rate (24, 25, 30, 48, 50, 60, 90,
/// 100, 120, 144, 240 fps and 30000/1001 fps) is a whole number of flicks, so frame durations add
/// up without rounding. A signed 64-bit count covers about 414 years.
using Flicks = std::int64_t;

inline constexpr Flicks kFlicksPerSecond = 705'600'000;

/// A frame rate as an exact ratio of integers (30000/1001 for NTSC video).
struct FrameRate {
  std::int64_t numerator = 60;
  std::int64_t denominator = 1;
};

/// Duration of one frame at `rate`, in flicks. Throws when the rate is not positive or its frame
/// is not a whole number of flicks (a rate whose frames would drift against the clock).
Flicks frameDuration(FrameRate rate);

/// Duration of `seconds` rounded to the nearest flick (for user-facing inputs such as a list of
/// frame times; the result is exact from then on).
Flicks flicksFromSeconds(double seconds);

/// Seconds of a flick count, for reporting only: the simulation never reads time back as a float.
inline double secondsFromFlicks(Flicks f) { return static_cast<double>(f) / kFlicksPerSecond; }

}  // namespace tickfx
