#include "particles/FixedStepDriver.h"

#include <cmath>
#include <stdexcept>

namespace tickfx {

FixedStepDriver::FixedStepDriver(std::int64_t stepRateHz, std::int64_t maxTicksPerAdvance,
                                 OverrunPolicy policy)
    : stepRate_(stepRateHz), maxTicks_(maxTicksPerAdvance), policy_(policy) {
  if (stepRateHz <= 0 || stepRateHz > 1'000'000) {
    throw std::invalid_argument("step rate must be in [1, 1000000] Hz");
  }
  if (maxTicksPerAdvance <= 0) throw std::invalid_argument("max ticks per frame must be > 0");
}

AdvanceResult FixedStepDriver::advance(Flicks frame) {
  if (frame < 0) throw std::invalid_argument("frame duration must be >= 0");
  // One tick is exactly kFlicksPerSecond units of (flick · Hz); 128 bits keep a long frame at a
  // high step rate from overflowing before the division.
  const __int128 total =
      static_cast<__int128>(remainder_) + static_cast<__int128>(frame) * stepRate_;
  const __int128 whole = total / kFlicksPerSecond;
  AdvanceResult result;
  result.ticks = whole > maxTicks_ ? maxTicks_ : static_cast<std::int64_t>(whole);
  const __int128 excess = whole - result.ticks;
  if (policy_ == OverrunPolicy::DropExcess) {
    result.ticksDropped = static_cast<std::int64_t>(excess);
    ticksDropped_ += result.ticksDropped;
    remainder_ = static_cast<std::int64_t>(total % kFlicksPerSecond);
  } else {
    result.ticksPending = static_cast<std::int64_t>(excess);
    remainder_ =
        static_cast<std::int64_t>(total - static_cast<__int128>(result.ticks) * kFlicksPerSecond);
  }
  ticksIssued_ += result.ticks;
  result.alpha = alpha();
  return result;
}

float FixedStepDriver::alpha() const {
  // While ticks are owed the newest state is behind the frame: show the newest state as nearly
  // as α < 1 allows rather than extrapolate past it.
  if (remainder_ >= kFlicksPerSecond) return std::nextafter(1.0f, 0.0f);
  // kFlicksPerSecond = 2^9 · 1378125 is exact in a float; the quotient is rounded once and can
  // reach 1.0 only by that rounding, which the clamp undoes.
  const float a = static_cast<float>(remainder_) / static_cast<float>(kFlicksPerSecond);
  return a < 1.0f ? a : std::nextafter(1.0f, 0.0f);
}

void FixedStepDriver::restore(std::int64_t ticksIssued, std::int64_t ticksDropped,
                              std::int64_t remainder) {
  if (ticksIssued < 0 || ticksDropped < 0 || remainder < 0) {
    throw std::invalid_argument("driver state must not be negative");
  }
  ticksIssued_ = ticksIssued;
  ticksDropped_ = ticksDropped;
  remainder_ = remainder;
}

}  // namespace tickfx
