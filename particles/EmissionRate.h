// How many particles a rate emission has made by the end of each tick, in exact integers.
#pragma once

#include <cstdint>

namespace tickfx {

/// Rate emission of R particles a second over [start, stop). The n-th particle (n = 1, 2, ...)
/// accrues at start + n/R, while start + n/R <= stop, and is born at the start of the tick in
/// which it accrues: by the end of tick k (time (k+1)/H) ⌊R·(min((k+1)/H, stop) − start)⌋ have
/// been made, and a whole emission makes ⌊R·(stop − start)⌋, whatever the step rate.
///
/// start and stop are taken as the decimals they were written as (the shortest decimal that
/// reads back as the same double, so 0.3 is 3/10, not the binary fraction just below it) and R
/// as a whole number of 10⁻⁶ particle/s; everything after that is exact rational arithmetic.
class EmissionRate {
 public:
  /// Rate units (particles per 10⁶ s) in one particle per second.
  static constexpr std::int64_t kMicrosPerSecond = 1'000'000;

  /// `rateMicros` particles per 10⁶ s (>= 0), `start` >= 0, `stop` >= start (+∞ for never),
  /// both in seconds and at most 1e9 (or +∞ for stop); `stepRateHz` > 0.
  EmissionRate(std::int64_t rateMicros, double start, double stop, std::int64_t stepRateHz);

  /// Particles made by ticks 0 to `tick` (0 for tick < 0).
  std::uint64_t madeThrough(std::int64_t tick) const;

 private:
  std::int64_t rateMicros_;
  std::int64_t stepRate_;
  // Ticks before firstTick_ make none; from lastTick_ on, total_ have been made. In between the
  // count is ⌊R·(k+1)/(10⁶·H)⌋ − startWhole_ − [its remainder < startThreshold_].
  std::int64_t firstTick_ = 0;
  std::int64_t lastTick_ = 0;
  std::uint64_t total_ = 0;
  __int128 startWhole_ = 0;
  __int128 startThreshold_ = 0;
};

}  // namespace tickfx
