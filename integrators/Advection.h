// Advection: the first-order flow x' = u(x, t) that a velocity-prescribing field imposes.
#pragma once

#include <string_view>

#include "fields/ForceSet.h"
#include "integrators/AdvectionScheme.h"
#include "integrators/StagePasses.h"

namespace tickfx {

struct StepTime;

/// Advances a pool along x' = u(x, t) by one tick. After the step the velocity column holds the
/// mean velocity the step moved each particle with (Euler: u(x, t); midpoint: the midpoint
/// sample; Heun and RK4: their weighted means), so a cache shows the velocity that carried it,
/// and previousPosition() the position before the step. Keeps scratch columns between calls:
/// one instance serves one pool.
class Advection {
 public:
  explicit Advection(AdvectionScheme scheme) : scheme_(scheme) {}
  AdvectionScheme scheme() const { return scheme_; }
  /// Advances `rows` (see StepRows). `afterEachTile`: as runPasses() takes it.
  void step(ParticlePool& pool, const ForceSet& forces, const StepTime& time, const StepRows& rows,
            const RowPass& afterEachTile = {});

 private:
  AdvectionScheme scheme_;
  StageScratch scratch_{7};  // k1..k4, then the stage positions x2 x3 x4
};

}  // namespace tickfx
