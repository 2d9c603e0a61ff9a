// The interface every time-stepping scheme implements.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fields/ForceSet.h"
#include "integrators/AdvectionScheme.h"
#include "integrators/StepRows.h"
#include "particles/NonfiniteState.h"
#include "particles/ParticlePool.h"

namespace tickfx {

class Advection;    // integrators/Advection.h, internal
struct StateBound;  // particles/StateBound.h

/// The tick being integrated: from t = tick/rate to (tick+1)/rate seconds.
struct StepTime {
  std::int64_t tick = 0;
  std::int64_t stepRateHz = 60;

  /// The step length in seconds, rounded to float once.
  float dt() const { return static_cast<float>(1.0 / static_cast<double>(stepRateHz)); }
  /// The instant `halves` half-steps into the tick (0, 1, 2: t, t + dt/2, t + dt).
  TickInstant stage(int halves) const { return {tick, halves, stepRateHz}; }
};

/// A time-stepping scheme. An integrator advances rows (all of the pool, or a block: StepRows) by
/// one tick, asking the forces for accelerations at the states and times its scheme needs, and
/// stores the position it started from in pool.previousPosition() when the step keeps it (for
/// interpolation: StepRows::keepPrevious) or the scheme reads it as state, else in the caller's
/// StepRows::starts where given (a block's collisions). Rows from
/// StepRows::fresh on were spawned this tick: schemes with history start them on their own.
///
/// When the forces prescribe velocity (advection, ForceSet::prescribesVelocity), step() runs the
/// scheme's first-order counterpart instead (advectionScheme(); see integrators/Advection.h).
///
/// Implementations keep scratch columns between calls, so one instance serves one pool.
class Integrator {
 public:
  Integrator();
  virtual ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;
  /// The name used in effect files ("semi_implicit_euler", ...).
  virtual std::string_view name() const = 0;
  /// Order of the global position error for smooth forces that depend on time only: 1, 2 or 4
  /// (see each scheme for position-dependent forces).
  virtual int order() const = 0;
  /// Force evaluations per tick (RK4: 4).
  virtual int evaluationsPerStep() const = 0;
  /// True when the scheme reads pool.previousPosition() as state (position Verlet's x_{n−1});
  /// the others only write it, for interpolation.
  virtual bool readsPreviousPosition() const { return false; }
  /// How this scheme advances x' = u(x, t) when the forces prescribe velocity.
  virtual AdvectionScheme advectionScheme() const = 0;

  /// Advances rows [0, pool.size()) by one tick: integrate(), or the advection scheme. With
  /// `check`, each tile's new positions and velocities are checked for non-finite values inside
  /// the scheme's last pass over it (see NonfiniteCheck); the state's bits are the same either way.
  /// `keepPrevious`: see StepRows::keepPrevious.
  void step(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
            NonfiniteCheck* check = nullptr, bool keepPrevious = true);

  /// Widens `bound` (of the magnitudes of the state of every row a tick steps: StateBound) to what
  /// they can be after tick `time`, by the scheme's own row kernel run on bounds
  /// (integrators/MagnitudeRows.h), and returns true; when bound.provesFinite() then holds, the
  /// tick makes no value that is not finite. False, `bound` untouched, where the scheme cannot
  /// say: under forces not in the one pass's forms (ForceSet::uniformAndDrag), and by default.
  virtual bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                         StateBound& bound) const;
  /// For a scheme with a third state column (StateBound::extra: position Verlet's previous
  /// position, velocity Verlet's acceleration), widens bound.extra to what the scheme starts that
  /// column with for rows spawned for tick `time` within bound.position and bound.velocity, and
  /// returns whether it could (as boundTick()). The default, for the others: true, as there is
  /// nothing to start.
  virtual bool boundSpawned(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                            StateBound& bound) const;

  /// Readies the pool's columns and this integrator for `forces` (velocity Verlet's kept
  /// acceleration, the advection scheme), so that stepRows() may then run on disjoint blocks
  /// from several threads at once. step() does it itself.
  void prepare(ParticlePool& pool, const ForceSet& forces);

  /// step() for `rows` alone, after prepare(). Calls for disjoint blocks of rows may run at once
  /// when every force is local (ForceSet::isLocal): a fused frame's blocks. A row gets the same
  /// bits as from step().
  void stepRows(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                const StepRows& rows, NonfiniteCheck* check);

 protected:
  /// The scheme itself, under forces that add acceleration, over `rows`. With `check` set, the
  /// scheme checks the values its last update loop writes, in that loop (updateComponents()), or by
  /// the exception flags after each tile (tileCheck(); both in integrators/CheckedRows.h). Called
  /// concurrently for disjoint blocks (see stepRows()): it writes nothing of the integrator's own
  /// but its scratch in split passes.
  virtual void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                         const StepRows& rows, NonfiniteCheck* check) = 0;

  /// Pool columns the scheme keeps from tick to tick (velocity Verlet's acceleration).
  virtual void prepareColumns(ParticlePool& /*pool*/) const {}

 private:
  std::unique_ptr<Advection> advection_;  // made by the first prepare() that advects
};

/// The integrator called `name`; throws std::invalid_argument for an unknown name.
std::unique_ptr<Integrator> makeIntegrator(std::string_view name);

/// Every name makeIntegrator accepts, in the order of the integrator study.
const std::vector<std::string>& integratorNames();

}  // namespace tickfx
