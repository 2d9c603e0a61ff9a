#include "particles/ExactTime.h"

#include <cmath>
#include <stdexcept>

namespace tickfx::exact {

Dyadic dyadic(double x) {
  if (!(x >= 0.0 && x < 0x1p53)) throw std::invalid_argument("dyadic needs 0 <= x < 2^53");
  int e = 0;
  const double fraction = std::frexp(x, &e);
  return {static_cast<std::uint64_t>(std::ldexp(fraction, 53)), 53 - e};
}

std::int64_t tickAtOrAfter(double seconds, std::int64_t stepRateHz) {
  if (!std::isfinite(seconds) || seconds < 0.0 || seconds > 1.0e9) {
    throw std::invalid_argument("time must be a number of seconds in [0, 1e9]");
  }
  if (stepRateHz <= 0) throw std::invalid_argument("step rate must be positive");
  // ⌈seconds · H⌉ exactly: seconds = m / 2^shift with m < 2^53, so m · H < 2^73 fits in 128
  // bits and the power of two is a right shift (by at least 23: seconds <= 1e9 < 2^30).
  const Dyadic d = dyadic(seconds);
  const u128 scaled = static_cast<u128>(d.numerator) * static_cast<u128>(stepRateHz);
  const int shift = d.shift;
  u128 ceil = 0;
  if (shift < 128) {
    const u128 whole = scaled >> shift;
    ceil = whole + ((whole << shift) != scaled ? 1 : 0);
  } else {
    ceil = scaled != 0 ? 1 : 0;  // below 2^-75 s: any positive time is after tick 0
  }
  const auto k = static_cast<std::int64_t>(ceil);
  // Tick k − 1 is before `seconds` exactly, but its double may be `seconds` itself: the time
  // was written as (k − 1)/H. IEEE division of two exact doubles is rounded once, correctly.
  if (k > 0 && static_cast<double>(k - 1) / static_cast<double>(stepRateHz) == seconds) {
    return k - 1;
  }
  return k;
}

float fractionToFloat(u128 num, u128 den) {
  if (num == 0) return 0.0f;
  if (num >= den || den >= (u128{1} << 127)) {
    throw std::invalid_argument("fractionToFloat needs num < den < 2^127");
  }
  // Long division, one bit at a time: skip to the leading one bit of the quotient, then take 24
  // significant bits and round the rest (a guard bit and a sticky remainder), as IEEE does.
  int exponent = 0;
  u128 rem = num;
  while (rem < den) {  // rem < 2·den < 2^128 throughout
    rem <<= 1;
    --exponent;
  }
  std::uint32_t significand = 0;
  for (int bit = 0; bit < 24; ++bit) {
    significand <<= 1;
    if (rem >= den) {
      significand |= 1;
      rem -= den;
    }
    rem <<= 1;
  }
  // `rem` is now twice the remainder: compare it with den for the half-way point.
  if (rem > den || (rem == den && (significand & 1) != 0)) ++significand;
  // The quotient is significand · 2^(exponent − 23); significand may have rounded up to 2^24.
  return std::ldexp(static_cast<float>(significand), exponent - 23);
}

}  // namespace tickfx::exact
