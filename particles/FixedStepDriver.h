// Turns variable frame durations into a whole number of fixed ticks plus an exact remainder.
#pragma once

#include <cstdint>

#include "particles/Clock.h"

namespace tickfx {

/// What to do when a frame asks for more ticks than `maxTicksPerAdvance` (the spiral of death:
/// a slow frame makes the next one slower still).
enum class OverrunPolicy {
  /// Run the cap and forget the rest of the whole ticks; the fraction is kept, so α stays smooth.
  /// The simulation then lags wall time by the dropped ticks, for good.
  DropExcess,
  /// Run the cap and keep the debt: later, shorter frames catch up.
  FallBehind,
};

/// What one call to FixedStepDriver::advance decided.
struct AdvanceResult {
  /// Ticks the caller must run now, in order.
  std::int64_t ticks = 0;
  /// Whole ticks discarded by the cap in this call (DropExcess only).
  std::int64_t ticksDropped = 0;
  /// Whole ticks still owed after this call (FallBehind only).
  std::int64_t ticksPending = 0;
  /// Where the frame lies between the last two ticks, in [0, 1): render lerp(previous, current, α).
  float alpha = 0.0f;
};

/// The fixed-step clock. It keeps the time that has not yet become a tick as an integer in units
/// of 1/(kFlicksPerSecond · stepRate) s, so no frame sequence can lose or invent time: after frames
/// summing to T flicks exactly floor(T · stepRate / kFlicksPerSecond) ticks have run (minus any the
/// cap dropped), whatever the individual durations were.
class FixedStepDriver {
 public:
  /// `stepRateHz` ticks per second (> 0); at most `maxTicksPerAdvance` ticks per call (> 0).
  FixedStepDriver(std::int64_t stepRateHz, std::int64_t maxTicksPerAdvance,
                  OverrunPolicy policy = OverrunPolicy::DropExcess);

  /// Adds one frame of `frame` flicks (>= 0) and says how many ticks to run and the new α.
  AdvanceResult advance(Flicks frame);

  std::int64_t stepRateHz() const { return stepRate_; }
  std::int64_t maxTicksPerAdvance() const { return maxTicks_; }
  OverrunPolicy policy() const { return policy_; }
  /// Ticks handed out so far (the simulation's tick counter once the caller has run them).
  std::int64_t ticksIssued() const { return ticksIssued_; }
  /// Ticks discarded by the cap since construction.
  std::int64_t ticksDroppedTotal() const { return ticksDropped_; }
  /// The remainder in units of 1/(kFlicksPerSecond · stepRate) s; with the counters above it is
  /// the driver's whole state (what a checkpoint stores).
  std::int64_t remainder() const { return remainder_; }
  void restore(std::int64_t ticksIssued, std::int64_t ticksDropped, std::int64_t remainder);

 private:
  float alpha() const;

  std::int64_t stepRate_;
  std::int64_t maxTicks_;
  OverrunPolicy policy_;
  std::int64_t ticksIssued_ = 0;
  std::int64_t ticksDropped_ = 0;
  // Always in [0, kFlicksPerSecond) after advance() under DropExcess; may hold whole owed ticks
  // under FallBehind.
  std::int64_t remainder_ = 0;
};

}  // namespace tickfx
