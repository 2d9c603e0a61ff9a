// A proof, before a fused frame runs, that its ticks cannot leave the finite range: bounds of the
// state's magnitudes, measured where the rows are in cache and carried through each tick by the
// scheme (Integrator::boundTick, integrators/MagnitudeRows.h). Under NonfinitePolicy::Stop a
// frame that cannot go non-finite needs no copy of its start to go back to (ParticleSystem's
// fused frames; what the copy costs: docs/performance.md).
#pragma once

#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "particles/ParticlePool.h"

namespace tickfx {

/// Upper bounds of |x| over every component of every row's state: position (m), velocity (m/s)
/// and the scheme's third column where it has one (extraColumnOf()).
struct StateBound {
  double position = 0.0;
  double velocity = 0.0;
  double extra = 0.0;

  /// The largest magnitude a bound may reach and still prove a tick finite: every value a tick
  /// computes stays below it, so no operation overflows (FLT_MAX is about 2¹²⁸) and, its operands
  /// finite, none makes a NaN.
  static constexpr double kLimit = 0x1p126;

  /// Whether every bound is at most kLimit (false for a NaN).
  bool provesFinite() const { return position <= kLimit && velocity <= kLimit && extra <= kLimit; }
};

/// The larger of each pair of bounds, a NaN where either is one.
inline double wider(double a, double b) {
  return std::isnan(a) || std::isnan(b) ? NAN : a < b ? b : a;
}
inline StateBound wider(const StateBound& a, const StateBound& b) {
  return {wider(a.position, b.position), wider(a.velocity, b.velocity), wider(a.extra, b.extra)};
}

/// The state column beyond the position and velocity that a scheme reads from tick to tick:
/// position Verlet's previous position (`readsPrevious`), velocity Verlet's kept acceleration;
/// nullptr for the others.
inline const Vec3Column* extraColumnOf(const ParticlePool& pool, bool readsPrevious) {
  if (readsPrevious) return &pool.previousPosition();
  return pool.keepsAcceleration() ? &pool.acceleration() : nullptr;
}
inline Vec3Column* extraColumnOf(ParticlePool& pool, bool readsPrevious) {
  return const_cast<Vec3Column*>(extraColumnOf(std::as_const(pool), readsPrevious));
}

/// The largest magnitude among values [begin, end) of `column`, as the bits of a float (sign
/// cleared; non-negative floats order as their bits): +∞ or a NaN when one is not finite. The
/// same whatever the order the rows are taken in.
std::uint32_t magnitudeBits(const float* column, std::size_t begin, std::size_t end);

/// The float whose bits magnitudeBits() gave, as a bound: +∞ for an infinity or a NaN.
double boundOfBits(std::uint32_t bits);

/// The largest magnitudes of the state of the rows added, from any threads in any order (a max:
/// the same bound whatever the split).
class LargestMagnitudes {
 public:
  /// Takes in rows [begin, end) of `pool`'s positions and velocities, and of `extra` unless null
  /// (extraColumnOf()).
  void add(const ParticlePool& pool, const Vec3Column* extra, std::size_t begin, std::size_t end);
  /// The bound of every row added (0 for none; +∞ where one was not finite).
  StateBound bound() const;

 private:
  std::atomic<std::uint32_t> bits_[3] = {0, 0, 0};  // position, velocity, extra
};

}  // namespace tickfx
