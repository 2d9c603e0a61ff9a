// Exact arithmetic between times given in seconds (doubles) and the integer tick grid.
//
// Mapping a time to a tick through a float product, or through the nearest flick, can land one
// tick late when k/H is not a whole number of flicks. These helpers decide in exact integers.
#pragma once

#include <cstdint>

namespace tickfx::exact {

using u128 = unsigned __int128;

/// A double x in [0, 2^53) as numerator / 2^shift exactly, numerator < 2^53 and shift >= 0
/// (frexp and ldexp are exact): the form in which a time or a rate in seconds meets integers.
/// Throws std::invalid_argument outside that range.
struct Dyadic {
  std::uint64_t numerator = 0;
  int shift = 0;
};
Dyadic dyadic(double x);

/// The first tick k whose time k / stepRateHz, rounded to the nearest double, is at or after
/// `seconds` (finite, in [0, 1e9]). So a time written as k/H in any form that reads back as the
/// double nearest k/H (0.1 at 10 Hz, 1/1024 at 1024 Hz, 1.0/3 at 3 Hz) is tick k exactly, and no
/// time is ever mapped to a tick before it. Throws std::invalid_argument out of range.
std::int64_t tickAtOrAfter(double seconds, std::int64_t stepRateHz);

/// num / den rounded to the nearest float (ties to even) once, for 0 <= num < den < 2^127: a
/// fraction of a tick or of a frame computed from integers (an interpolation factor, a blend
/// weight) without the double rounding of float(double(num) / double(den)).
float fractionToFloat(u128 num, u128 den);

}  // namespace tickfx::exact
