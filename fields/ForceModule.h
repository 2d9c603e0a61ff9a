// The boundary between the integrators and everything that pushes particles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "particles/ParticlePool.h"
#include "particles/RowViews.h"
#include "particles/TickInstant.h"

namespace tickfx {

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

/// The integer coordinates of a block of a grid (ForceModule::sampleBlocks).
struct BlockCoord {
  std::int32_t x = 0, y = 0, z = 0;
  /// x of a position that is in no block: a non-finite one, or one far outside any grid.
  static constexpr std::int32_t kNowhere = INT32_MIN;
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

  /// Advection modules: true when accumulateVelocity() reads nothing of its input but the
  /// positions of its rows and the instant (no pool column, no velocity), so that it may be handed
  /// positions gathered from any rows, in any order, as rows [0, n) of a buffer
  /// (ForceSet::evaluateVelocityGathered). False unless a module says so.
  virtual bool velocityFromPositionsOnly() const { return false; }

  /// Advection modules that sample a grid: writes to out[j] the coordinates of the block of the
  /// grid (an OpenVDB leaf node) whose values a sample at the position of row rows.begin + j
  /// reads first, and returns true. Integrators visit particles block by block with it
  /// (integrators/LeafOrder.h) so that consecutive samples share the block's memory and its
  /// lookup: it orders visits and nothing else, so it need not be exact, only cheap and the same
  /// for the same position. A position the grid cannot place (not finite, or beyond ±2^30
  /// voxels) gets BlockCoord::kNowhere. False (the default): the module has no such blocks.
  virtual bool sampleBlocks(const Vec3View& /*position*/, RowRange /*rows*/,
                            BlockCoord* /*out*/) const {
    return false;
  }

  /// Called once per tick after the step, with the state at the end of the tick (`end` is
  /// the tick's instant t + dt): a module may flag particles dead here (a field's kill region).
  /// The pool removes them before the next tick. Must give the same flags on any thread count.
  virtual void endTick(ParticlePool& /*pool*/, const TickInstant& /*end*/) {}
};

}  // namespace tickfx
