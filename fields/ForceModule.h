// The boundary between the integrators and everything that pushes particles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "particles/Assert.h"
#include "particles/ParticlePool.h"

namespace tickfx {

/// Rows [begin, end) of the pool.
struct RowRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  Eigen::Index offset() const { return static_cast<Eigen::Index>(begin); }
  Eigen::Index count() const { return static_cast<Eigen::Index>(end - begin); }
};

/// Writable values of three components for the rows of one RowRange: element j of each map
/// belongs to pool row range.begin + j.
struct Vec3Rows {
  Eigen::Map<FloatColumn> x, y, z;

  Vec3Rows(float* px, float* py, float* pz, Eigen::Index n) : x(px, n), y(py, n), z(pz, n) {}
  /// Rows `r` of a pool-sized column.
  static Vec3Rows of(Vec3Column& c, RowRange r) {
    TICKFX_ASSERT(r.begin <= r.end && r.end <= static_cast<std::size_t>(c.x.size()),
                  "a row range past the end of its column");
    return {c.x.data() + r.begin, c.y.data() + r.begin, c.z.data() + r.begin, r.count()};
  }
  Eigen::Map<FloatColumn>& operator[](int c) { return c == 0 ? x : (c == 1 ? y : z); }
};

/// Read-only values of three components for the rows of one RowRange.
struct ConstVec3Rows {
  Eigen::Map<const FloatColumn> x, y, z;

  ConstVec3Rows(const float* px, const float* py, const float* pz, Eigen::Index n)
      : x(px, n), y(py, n), z(pz, n) {}
  const Eigen::Map<const FloatColumn>& operator[](int c) const {
    return c == 0 ? x : (c == 1 ? y : z);
  }
};

/// A vector quantity an integrator hands to the forces: row r is at index r − base of each
/// component. The pool's own columns have base 0 and hold every row; an integrator's scratch in a
/// fused pass holds only the rows of the current tile (base = the tile's first row), which is
/// enough because a fused pass only ever runs local modules.
struct Vec3View {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  std::size_t base = 0;

  static Vec3View of(const Vec3Column& c) { return {c.x.data(), c.y.data(), c.z.data(), 0}; }
  /// The values of rows `r`.
  ConstVec3Rows rows(RowRange r) const {
    TICKFX_ASSERT(r.begin >= base && r.begin <= r.end, "rows read below a view's base");
    const std::size_t i = r.begin - base;
    return {x + i, y + i, z + i, r.count()};
  }
  /// The value of one row (non-local modules: any row of a base-0 view).
  Eigen::Vector3f at(std::size_t row) const {
    TICKFX_ASSERT(row >= base, "a row read below a view's base");
    const std::size_t i = row - base;
    return {x[i], y[i], z[i]};
  }
};

/// An instant of a tick in integers: `halves` half-steps (0, 1 or 2: t, t + dt/2, t + dt, the
/// times the integrators' stages are at) past tick `tick` at `stepRateHz`. Modules that must place
/// the time exactly (a field sequence's frame) use the integers; the rest seconds().
struct TickInstant {
  std::int64_t tick = 0;
  int halves = 0;
  std::int64_t stepRateHz = 60;

  /// (tick + halves/2) / stepRateHz seconds, rounded once from exact operands.
  double seconds() const {
    return (static_cast<double>(tick) + 0.5 * halves) / static_cast<double>(stepRateHz);
  }
};

/// The state at which an integrator asks for accelerations: the pool's own columns or an
/// integrator's stage values (RK4's midpoints). Everything else (mass, ids, attributes) comes
/// from `pool`, indexed by pool row.
struct ForceInput {
  const ParticlePool& pool;
  Vec3View position;  // metres
  Vec3View velocity;  // metres per second
  TickInstant at;     // the stage asked (t, t + dt/2, t + dt) of the tick being integrated

  /// Seconds since tick 0 at the stage asked.
  double time() const { return at.seconds(); }
};

/// A force module adds acceleration (m/s²) to particles. Modules are composed in an ordered list
/// (ForceSet) and evaluated in that order, so the floating-point sum is the same on every run.
///
/// Threading: accumulate() is called concurrently for disjoint row ranges and must write only
/// the rows it is given (gather, never scatter). A local module reads only those rows of the
/// input; a non-local one (springs) may read any row. Per-thread caches (an OpenVDB value
/// accessor, say) belong inside accumulate(), built per call.
class ForceModule {
 public:
  virtual ~ForceModule() = default;

  /// The module's type as written in effect files ("gravity", "drag", ...).
  virtual std::string_view typeName() const = 0;

  /// True when a particle's acceleration depends on its own row only. Integrators then fuse all
  /// their passes over a small tile of rows; a module reading other rows must say false.
  virtual bool isLocal() const { return true; }

  /// True when the module may be evaluated for several ticks at once, blocks of rows apart: it
  /// is local, its beginTick() and endTick() do nothing, and what it adds depends on the row's
  /// state and the instant alone. A system whose modules all say so advances a frame's ticks
  /// block by block (ParticleSystem, fused frames). False unless a module says otherwise.
  virtual bool interleavesTicks() const { return false; }
  /// True when, at finite positions and velocities, the module's acceleration is made by
  /// arithmetic from those values and finite constants alone (no grid or table values, which may
  /// already be NaN): it is then non-finite only through an operation that raises a
  /// floating-point exception (invalid, overflow, divide-by-zero), and the integrators may check
  /// ticks under it by the exception flags (NonfiniteCheck). False unless a module says so.
  virtual bool arithmeticOnly() const { return false; }
  /// When the acceleration at `in` is the same for every particle, stores it in `a` and returns
  /// true. ForceSet then adds a leading run of such modules once per evaluation instead of once
  /// per particle; the per-particle sum keeps the same order, so the bits do not change.
  virtual bool uniformAcceleration(const ForceInput& /*in*/, Eigen::Vector3f& /*a*/) const {
    return false;
  }

  /// When the module is a linear drag, a += k·(air − v) per component in that order of operations,
  /// stores k (1/s) and air (m/s) and returns true: a scheme may then form the acceleration inside
  /// its own update loop (ForceSet::uniformAndDrag).
  virtual bool linearDrag(float& /*k*/, Eigen::Vector3f& /*air*/) const { return false; }
  /// Called once per tick, on one thread, before any accumulate(): rebuild per-tick tables.
  virtual void beginTick(const ParticlePool& /*pool*/, std::int64_t /*tick*/) {}

  /// Adds this module's acceleration at `in` to `acceleration`, whose element j is row
  /// rows.begin + j. Not called for a module that prescribes velocity.
  virtual void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const = 0;

  /// True for an advection module: it sets the particles' velocity (v := u(x, t)) instead of
  /// adding acceleration. The state then follows the first-order equation x' = u(x, t) (see
  /// integrators/Advection.h); a ForceSet refuses to mix such modules with acceleration modules,
  /// whose forces would be silently ignored.
  virtual bool prescribesVelocity() const { return false; }

  /// Advection modules: adds this module's velocity (m/s) at `in` to `velocity`, whose element j
  /// is row rows.begin + j. Same threading rules as accumulate().
  virtual void accumulateVelocity(const ForceInput& /*in*/, RowRange /*rows*/,
                                  Vec3Rows& /*velocity*/) const {}

  /// Called once per tick after the step, with the state at the end of the tick (`end` is
  /// the tick's instant t + dt): a module may flag particles dead here (a field's kill region).
  /// The pool removes them before the next tick. Must give the same flags on any thread count.
  virtual void endTick(ParticlePool& /*pool*/, const TickInstant& /*end*/) {}
};

}  // namespace tickfx
