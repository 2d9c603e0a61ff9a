// State that is no longer a number: an unstable step (explicit Euler on a stiff spring), a force
// that divides by zero. What the system does when a tick makes some, and what it reports.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "particles/ParticlePool.h"
#include "particles/RelaxedFlag.h"

namespace tickfx {

/// What a tick does with particles whose position or velocity stopped being finite (±inf, NaN).
enum class NonfinitePolicy : std::uint8_t {
  /// The system runs no more ticks and reports the event (ParticleSystem::nonfiniteStop()); the
  /// state stays the one the tick made, non-finite rows included, to be looked at.
  Stop,
  /// Such particles die at the end of the tick, counted (ParticleSystem::nonfiniteKilled()).
  Kill,
  /// Nothing is checked: non-finite values stay in the state and in whatever is written from it.
  Keep,
};

/// "stop", "kill", "keep": the names effect files use, in the order of the enumerators.
const std::vector<std::string>& nonfinitePolicyNames();
/// The policy called `name`; throws std::invalid_argument naming the choices for any other.
NonfinitePolicy nonfinitePolicyNamed(std::string_view name);
std::string_view nameOf(NonfinitePolicy policy);

/// The first tick that left particles non-finite, under NonfinitePolicy::Stop.
struct NonfiniteEvent {
  /// The ticks done when it happened: the state at tick / stepRateHz seconds is the first with
  /// non-finite values (the state at (tick − 1) / stepRateHz was finite).
  std::int64_t tick = 0;
  std::int64_t stepRateHz = 0;
  /// How many particles have a non-finite position or velocity component.
  std::size_t particles = 0;
  /// The ids of the first of them (at most kIdsKept), in increasing order.
  std::vector<std::uint64_t> firstIds;

  static constexpr std::size_t kIdsKept = 8;

  double seconds() const { return static_cast<double>(tick) / static_cast<double>(stepRateHz); }
  /// "tick 95 (t = 3.16666667 s): 24 particles have a non-finite position or velocity (ids 0,
  /// 1, 2, 3, 4, 5, 6, 7, ...)".
  std::string describe() const;
};

/// Finds non-finite positions and velocities. An integrator's last update loop over a tile sums
/// the values it writes as it writes them (integrators/CheckedRows.h) and calls scan() only for a
/// tile whose sum is not finite; over rows that start finite, a scheme's one pass, and its force
/// passes under local, arithmetic-only forces (ForceModule::arithmeticOnly), test the
/// floating-point exception flags after each tile instead (steppedRowsFinite()); the advection
/// schemes call scan() for every tile once their passes are done with it, while the tile is in
/// cache. scan() sums the tile's six columns (one add per value), finite unless a value is not
/// (or the sum overflows), and tests each row only then.
/// Rows found get kFlag in the pool's dead flags. scan() may run on disjoint rows from several
/// threads; what it flags does not depend on how rows are split.
class NonfiniteCheck {
 public:
  /// The bit of ParticlePool::dead() that marks a non-finite row (1 is an ordinary death).
  static constexpr std::uint8_t kFlag = 2;

  /// Checks rows [begin, end).
  void scan(ParticlePool& pool, std::size_t begin, std::size_t end);
  /// Whether any scan() since the last clear() flagged a row.
  bool found() const { return found_.get(); }
  void clear() { found_.clear(); }

  /// Whether the rows a tick steps (all but those spawned for it) are known to be finite when it
  /// starts: the tick before them was checked and nothing has written the state since
  /// (ParticleSystem keeps this; false by default). Where the tick's other inputs are finite
  /// constants too, a scheme then checks them by the floating-point exceptions its arithmetic
  /// raises (integrators/NonfiniteExceptions.h), at no cost per value, and scans the spawned rows.
  bool steppedRowsFinite() const { return steppedRowsFinite_; }
  void setSteppedRowsFinite(bool finite) { steppedRowsFinite_ = finite; }

 private:
  RelaxedFlag found_;
  bool steppedRowsFinite_ = false;
};

}  // namespace tickfx
