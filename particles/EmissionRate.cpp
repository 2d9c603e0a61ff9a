#include "particles/EmissionRate.h"

#include <boost/multiprecision/cpp_int.hpp>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tickfx {
namespace {

using Big = boost::multiprecision::cpp_int;

// `seconds` as the shortest decimal that reads back as it: numerator / 10^scale, exactly.
struct Decimal {
  Big numerator;
  int scale = 0;
};

Decimal decimalOf(double seconds) {
  char text[64];
  const auto [end, ec] =
      std::to_chars(text, text + sizeof text, seconds, std::chars_format::scientific);
  if (ec != std::errc()) throw std::invalid_argument("time cannot be written as a decimal");
  // d.dddde±x: the digits without the point, and the power of ten of the last one.
  const std::string s(text, end);
  const std::size_t e = s.find('e');
  std::string digits;
  for (std::size_t i = 0; i < e; ++i) {
    if (s[i] != '.') digits += s[i];
  }
  const int exponent = std::stoi(s.substr(e + 1));
  Decimal d;
  d.numerator = Big(digits);
  const int scale = static_cast<int>(digits.size()) - 1 - exponent;
  if (scale >= 0) {
    d.scale = scale;
  } else {
    d.numerator *= boost::multiprecision::pow(Big(10), static_cast<unsigned>(-scale));
  }
  return d;
}

Big pow10(int n) { return boost::multiprecision::pow(Big(10), static_cast<unsigned>(n)); }

// ⌊a / b⌋ and ⌈a / b⌉ for a >= 0, b > 0.
Big floorDiv(const Big& a, const Big& b) { return a / b; }
Big ceilDiv(const Big& a, const Big& b) { return (a + b - 1) / b; }

}  // namespace

EmissionRate::EmissionRate(std::int64_t rateMicros, double start, double stop,
                           std::int64_t stepRateHz)
    : rateMicros_(rateMicros), stepRate_(stepRateHz) {
  if (rateMicros < 0 || stepRateHz <= 0 || !std::isfinite(start) || start < 0.0 || start > 1.0e9 ||
      std::isnan(stop) || stop < start || (std::isfinite(stop) && stop > 1.0e9)) {
    throw std::invalid_argument("emission rate settings out of range");
  }
  const Decimal s = decimalOf(start);
  const Big h(stepRateHz), r(rateMicros), perTick = Big(stepRateHz) * kMicrosPerSecond;
  // The first tick whose end is after start: k + 1 > start·H.
  firstTick_ = static_cast<std::int64_t>(floorDiv(s.numerator * h, pow10(s.scale)));
  // P(start) = R·start / 10⁶ particles; with Y = R·start·H (so P = Y / (10⁶·H)), a tick's count is
  // ⌊(R·(k+1) − Y) / (10⁶·H)⌋ = ⌊R·(k+1) / (10⁶·H)⌋ − ⌊P⌋ − [remainder < ⌈Y⌉ − ⌊P⌋·10⁶·H].
  const Big y = r * h * s.numerator;
  const Big wholeStart = floorDiv(floorDiv(y, pow10(s.scale)), perTick);
  startWhole_ = static_cast<__int128>(wholeStart);
  startThreshold_ = static_cast<__int128>(ceilDiv(y, pow10(s.scale)) - wholeStart * perTick);
  if (std::isinf(stop)) {
    lastTick_ = std::numeric_limits<std::int64_t>::max();
    return;
  }
  const Decimal t = decimalOf(stop);
  // The tick whose end reaches stop: (k + 1)/H >= stop.
  lastTick_ = static_cast<std::int64_t>(ceilDiv(t.numerator * h, pow10(t.scale))) - 1;
  // ⌊R·(stop − start) / 10⁶⌋ over the common denominator 10^max(scale).
  const int scale = std::max(s.scale, t.scale);
  const Big span = t.numerator * pow10(scale - t.scale) - s.numerator * pow10(scale - s.scale);
  total_ = static_cast<std::uint64_t>(floorDiv(r * span, pow10(scale) * kMicrosPerSecond));
}

std::uint64_t EmissionRate::madeThrough(std::int64_t tick) const {
  if (rateMicros_ == 0 || tick < firstTick_) return 0;
  if (tick >= lastTick_) return total_;
  const __int128 units = static_cast<__int128>(tick + 1) * rateMicros_;
  const __int128 perTick = static_cast<__int128>(stepRate_) * kMicrosPerSecond;
  return static_cast<std::uint64_t>(units / perTick - startWhole_ -
                                    (units % perTick < startThreshold_ ? 1 : 0));
}

}  // namespace tickfx
