// Explicit (forward) Euler: first order, gains energy on oscillators.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// p ← p + v·dt, then v ← v + a(p, v, t)·dt, both from the state at the start of the tick.
/// First order; on an undamped oscillator each step multiplies the energy by (1 + ω²dt²).
class ExplicitEuler final : public Integrator {
 public:
  std::string_view name() const override { return "explicit_euler"; }
  int order() const override { return 1; }
  int evaluationsPerStep() const override { return 1; }
  bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 StateBound& bound) const override;
  AdvectionScheme advectionScheme() const override { return AdvectionScheme::Euler; }

 protected:
  void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 const StepRows& rows, NonfiniteCheck* check) override;

 private:
  StageScratch scratch_{1};  // acceleration
};

}  // namespace tickfx
