#include "particles/FixedStepDriver.h"

#include <cmath>
#include <stdexcept>

#include "particles/Assert.h"
#include "particles/ExactTime.h"

namespace tickfx {
namespace {

// Far below 2^63 so that ticksDue + 1 and the sums in advance() never overflow; at 10⁶ Hz it
// is 146 000 years.
constexpr std::int64_t kMaxTicks = std::int64_t{1} << 62;

}  // namespace

FixedStepDriver::FixedStepDriver(std::int64_t stepRateHz, std::int64_t maxTicksPerAdvance,
                                 OverrunPolicy policy, FrameTiming timing)
    : stepRate_(stepRateHz), maxTicks_(maxTicksPerAdvance), policy_(policy), timing_(timing) {
  if (stepRateHz <= 0 || stepRateHz > 1'000'000) {
    throw std::invalid_argument("step rate must be in [1, 1000000] Hz");
  }
  if (maxTicksPerAdvance <= 0) throw std::invalid_argument("max ticks per frame must be > 0");
}

std::int64_t FixedStepDriver::target() const {
  const bool between = timing_ == FrameTiming::AtFrameTime && remainder_ > 0;
  return ticksDue_ + (between ? 1 : 0);
}

AdvanceResult FixedStepDriver::advance(Flicks frame) {
  if (frame < 0) throw std::invalid_argument("frame duration must be >= 0");
  // One tick is exactly kFlicksPerSecond units of (flick · Hz); 128 bits keep a long frame at a
  // high step rate, and a debt of many such frames, from overflowing.
  const __int128 total =
      static_cast<__int128>(remainder_) + static_cast<__int128>(frame) * stepRate_;
  const __int128 due = static_cast<__int128>(ticksDue_) + total / kFlicksPerSecond;
  if (due >= kMaxTicks) throw std::overflow_error("the driver's clock passed 2^62 ticks");
  ticksDue_ = static_cast<std::int64_t>(due);
  remainder_ = static_cast<std::int64_t>(total % kFlicksPerSecond);

  AdvanceResult result;
  const std::int64_t wanted = target() - ticksIssued_;
  result.ticks = wanted > maxTicks_ ? maxTicks_ : wanted;
  const std::int64_t excess = wanted - result.ticks;
  if (policy_ == OverrunPolicy::DropExcess) {
    // The clock itself moves back by the dropped ticks; its fraction stays, so α stays smooth.
    result.ticksDropped = excess;
    ticksDropped_ += excess;
    ticksDue_ -= excess;
  } else {
    result.ticksPending = excess;
  }
  ticksIssued_ += result.ticks;
  // The clock's invariants: its fraction of a tick is in [0, 1) tick, it never owes a negative
  // count, and nothing is issued past what is due (plus the tick a frame between ticks shows).
  TICKFX_ASSERT(remainder_ >= 0 && remainder_ < kFlicksPerSecond, "a clock remainder past a tick");
  TICKFX_ASSERT(result.ticks >= 0 && result.ticksDropped >= 0 && result.ticksPending >= 0,
                "a negative tick count from advance()");
  TICKFX_ASSERT(ticksIssued_ <= target(), "ticks issued past the clock's target");
  result.alpha = alpha();
  return result;
}

std::int64_t FixedStepDriver::frameOffset() const {
  // While ticks are owed the newest state is behind the frame: show it rather than extrapolate.
  if (ticksIssued_ < target()) return kFlicksPerSecond;
  if (timing_ == FrameTiming::AtFrameTime && remainder_ == 0) return kFlicksPerSecond;
  return remainder_;
}

float FixedStepDriver::alpha() const {
  const std::int64_t offset = frameOffset();
  if (offset == kFlicksPerSecond) {
    // One tick behind never reaches the newest tick's own state: α stays below 1.
    return timing_ == FrameTiming::AtFrameTime ? 1.0f : std::nextafter(1.0f, 0.0f);
  }
  const float a = exact::fractionToFloat(static_cast<exact::u128>(offset),
                                         static_cast<exact::u128>(kFlicksPerSecond));
  TICKFX_ASSERT(offset >= 0 && offset < kFlicksPerSecond, "a frame offset outside the tick");
  // Rounding can take offset/F within half an ulp of 1 up to 1.0f.
  return a < 1.0f || timing_ == FrameTiming::AtFrameTime ? a : std::nextafter(1.0f, 0.0f);
}

bool FixedStepDriver::canRestore(std::int64_t ticksIssued, std::int64_t ticksDropped,
                                 std::int64_t ticksDue, std::int64_t remainder) const {
  const bool between = timing_ == FrameTiming::AtFrameTime && remainder > 0;
  return ticksIssued >= 0 && ticksDropped >= 0 && ticksDue >= 0 && ticksDue < kMaxTicks &&
         remainder >= 0 && remainder < kFlicksPerSecond &&
         ticksIssued <= ticksDue + (between ? 1 : 0);
}

void FixedStepDriver::restore(std::int64_t ticksIssued, std::int64_t ticksDropped,
                              std::int64_t ticksDue, std::int64_t remainder) {
  if (!canRestore(ticksIssued, ticksDropped, ticksDue, remainder)) {
    throw std::invalid_argument("driver state out of range");
  }
  ticksIssued_ = ticksIssued;
  ticksDropped_ = ticksDropped;
  ticksDue_ = ticksDue;
  remainder_ = remainder;
}

}  // namespace tickfx
