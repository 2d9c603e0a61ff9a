// The boundary between the integrators and everything that pushes particles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "particles/ParticlePool.h"

namespace tickfx {

/// Rows [begin, end) of the pool.
struct RowRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  Eigen::Index offset() const { return static_cast<Eigen::Index>(begin); }
  Eigen::Index count() const { return static_cast<Eigen::Index>(end - begin); }
};

/// The state at which an integrator asks for accelerations. `position` and `velocity` may be the
/// pool's own columns or an integrator's stage columns (RK4's midpoints); both hold at least
/// pool.size() rows. Everything else (mass, ids, attributes) comes from `pool`.
struct ForceInput {
  const ParticlePool& pool;
  const Vec3Column& position;  // metres
  const Vec3Column& velocity;  // metres per second
  double time = 0.0;           // seconds since tick 0, exact to double for the stage asked
  std::int64_t tick = 0;       // the tick being integrated
};

/// A force module adds acceleration (m/s²) to particles. Modules are composed in an ordered list
/// (ForceSet) and evaluated in that order, so the floating-point sum is the same on every run.
///
/// Threading: accumulate() is called concurrently for disjoint row ranges and must write only
/// the rows it is given (gather, never scatter). It may read any row of the input. Per-thread
/// caches (an OpenVDB value accessor, say) belong inside accumulate(), built per call.
class ForceModule {
 public:
  virtual ~ForceModule() = default;

  /// The module's type as written in effect files ("gravity", "drag", ...).
  virtual std::string_view typeName() const = 0;

  /// True when a particle's acceleration depends on its own row only. Integrators then fuse the
  /// evaluation with the update in one pass; a module reading other rows (springs) must say false.
  virtual bool isLocal() const { return true; }

  /// Called once per tick, on one thread, before any accumulate(): rebuild per-tick tables.
  virtual void beginTick(const ParticlePool& /*pool*/, std::int64_t /*tick*/) {}

  /// Adds this module's acceleration at `in` to rows `rows` of `acceleration`.
  virtual void accumulate(const ForceInput& in, RowRange rows, Vec3Column& acceleration) const = 0;
};

}  // namespace tickfx
