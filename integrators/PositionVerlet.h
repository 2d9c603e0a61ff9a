// Position (Störmer) Verlet: second order, velocity derived from positions.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// p_new = 2p − p_prev + a(p, v, t)·dt², v = (p_new − p)/dt. The pool's previous-position column
/// is the history; a particle in its first tick is started with p_prev = p − v·dt + a·dt²/2, which
/// makes the first step p + v·dt + a·dt²/2 (exact for constant acceleration). The velocity is a
/// backward difference, first order, and it lags half a step.
class PositionVerlet final : public Integrator {
 public:
  std::string_view name() const override { return "position_verlet"; }
  int order() const override { return 2; }
  int evaluationsPerStep() const override { return 1; }
  void step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) override;

 private:
  StageScratch scratch_{2};  // acceleration, new position
};

}  // namespace tickfx
