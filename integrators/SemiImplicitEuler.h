// Semi-implicit (symplectic) Euler: first order, bounded energy.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// v ← v + a(p, v, t)·dt, then p ← p + v_new·dt. Symplectic: on an undamped oscillator the
/// energy oscillates about its true value instead of drifting (stable for ω·dt < 2).
class SemiImplicitEuler final : public Integrator {
 public:
  std::string_view name() const override { return "semi_implicit_euler"; }
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
