// An instant of a tick, in integers: where the integrators' stages are in time.
#pragma once

#include <cstdint>

namespace tickfx {

/// An instant of a tick in integers: `halves` half-steps (0, 1 or 2: t, t + dt/2, t + dt, the
/// times the integrators' stages are at) past tick `tick` at `stepRateHz`. Modules that must place
/// the time exactly (a field sequence's frame) use the integers; the rest seconds().
struct TickInstant {
  std::int64_t tick = 0;
  int halves = 0;
  std::int64_t stepRateHz = 60;

  /// (tick + halves/2) / stepRateHz seconds, rounded once from exact operands.
  double seconds() const {
    return (static_cast<double>(tick) + 0.5 * halves) / static_cast<double>(stepRateHz);
  }
};

}  // namespace tickfx
