// Turns variable frame durations into a whole number of fixed ticks plus an exact remainder.
#pragma once

#include <cstdint>

#include "particles/Clock.h"

namespace tickfx {

/// What to do when a frame asks for more ticks than `maxTicksPerAdvance` (the spiral of death:
/// a slow frame makes the next one slower still). Only hosts that advance in real time need a
/// cap; an offline run (`tickfx run`) lifts it and never drops a tick.
enum class OverrunPolicy {
  /// Run the cap and forget the rest of the whole ticks; the fraction is kept, so α stays smooth.
  /// The simulation then lags wall time by the dropped ticks, for good.
  DropExcess,
  /// Run the cap and keep the debt: later, shorter frames catch up.
  FallBehind,
};

/// Which time a frame shows (what α means).
enum class FrameTiming {
  /// A frame at time t shows the state at t. The driver runs every tick that starts before t
  /// (one tick past t when t falls between two ticks), and α places t between the last two
  /// ticks: α = 1 exactly when t falls on the newest tick. Caches and offline renders need this.
  AtFrameTime,
  /// Classic fixed-step rendering: the driver never runs a tick that ends after t, and α places
  /// t between the newest tick and the next one; interpolating the last two ticks by α then
  /// shows the state at t − dt (one tick of latency, no tick run ahead of the host's clock).
  OneTickBehind,
};

/// What one call to FixedStepDriver::advance decided.
struct AdvanceResult {
  /// Ticks the caller must run now, in order.
  std::int64_t ticks = 0;
  /// Whole ticks discarded by the cap in this call (DropExcess only).
  std::int64_t ticksDropped = 0;
  /// Whole ticks still owed after this call (FallBehind only).
  std::int64_t ticksPending = 0;
  /// Where the frame lies between the last two ticks, in [0, 1]: render
  /// lerp(previous, current, α). 1 means the current tick's own state, exactly.
  float alpha = 0.0f;
};

/// The fixed-step clock. It keeps the frame clock as whole ticks plus an integer remainder in
/// units of 1/(kFlicksPerSecond · stepRate) s, so no frame sequence can lose or invent time: after
/// frames summing to T flicks, the clock stands at exactly T · stepRate / kFlicksPerSecond ticks
/// (less any the cap dropped), whatever the individual durations were.
class FixedStepDriver {
 public:
  /// `stepRateHz` ticks per second (1 to 10⁶); at most `maxTicksPerAdvance` ticks per call (> 0).
  FixedStepDriver(std::int64_t stepRateHz, std::int64_t maxTicksPerAdvance,
                  OverrunPolicy policy = OverrunPolicy::DropExcess,
                  FrameTiming timing = FrameTiming::AtFrameTime);

  /// Adds one frame of `frame` flicks (>= 0) and says how many ticks to run and the new α.
  /// Throws std::overflow_error if the clock would pass 2^62 ticks.
  AdvanceResult advance(Flicks frame);

  std::int64_t stepRateHz() const { return stepRate_; }
  std::int64_t maxTicksPerAdvance() const { return maxTicks_; }
  OverrunPolicy policy() const { return policy_; }
  FrameTiming timing() const { return timing_; }
  /// Ticks handed out so far (the simulation's tick counter once the caller has run them).
  std::int64_t ticksIssued() const { return ticksIssued_; }
  /// Ticks discarded by the cap since construction.
  std::int64_t ticksDroppedTotal() const { return ticksDropped_; }
  /// Whole ticks the frame clock has passed (less those dropped): ⌊clock⌋ in ticks.
  std::int64_t ticksDue() const { return ticksDue_; }
  /// The clock's fraction past ticksDue(), in units of 1/(kFlicksPerSecond · stepRate) s, in
  /// [0, kFlicksPerSecond). With the counters above it is the driver's whole state (what a
  /// checkpoint stores).
  std::int64_t remainder() const { return remainder_; }
  /// Ticks the caller still owes the clock (FallBehind debt).
  std::int64_t ticksPending() const { return target() - ticksIssued_; }
  /// Where the last frame lies past tick ticksIssued() − 1, in the remainder's units, in
  /// [0, kFlicksPerSecond]: kFlicksPerSecond means on the newest tick. This is α as an exact
  /// integer (α is its float), for render copies that compute ages and the like from integers.
  std::int64_t frameOffset() const;
  /// α of the clock as it stands (what the last advance() returned).
  float alpha() const;

  /// Whether restore() takes this state: one that advance() can reach.
  bool canRestore(std::int64_t ticksIssued, std::int64_t ticksDropped, std::int64_t ticksDue,
                  std::int64_t remainder) const;
  /// Restores a saved state; throws std::invalid_argument unless canRestore().
  void restore(std::int64_t ticksIssued, std::int64_t ticksDropped, std::int64_t ticksDue,
               std::int64_t remainder);

 private:
  std::int64_t target() const;

  std::int64_t stepRate_;
  std::int64_t maxTicks_;
  OverrunPolicy policy_;
  FrameTiming timing_;
  std::int64_t ticksIssued_ = 0;
  std::int64_t ticksDropped_ = 0;
  std::int64_t ticksDue_ = 0;
  std::int64_t remainder_ = 0;  // in [0, kFlicksPerSecond)
};

}  // namespace tickfx
