// The midpoint (modified Euler) method: second order.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// v_mid = v + a(p, v, t)·dt/2; p ← p + v_mid·dt; v ← v + a(p_new, v_mid, t + dt/2)·dt.
/// Exact for constant acceleration and second order for forces that depend on time only (a
/// periodic wind). The second evaluation reads the *new* position, as the scheme is specified
/// (a field is sampled where the particle now is), which makes it first order for forces that
/// depend on position: on an undamped spring it loses energy every step. Not symplectic.
class Midpoint final : public Integrator {
 public:
  std::string_view name() const override { return "midpoint"; }
  int order() const override { return 2; }
  int evaluationsPerStep() const override { return 2; }
  bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 StateBound& bound) const override;
  AdvectionScheme advectionScheme() const override { return AdvectionScheme::Midpoint; }

 protected:
  void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 const StepRows& rows, NonfiniteCheck* check) override;

 private:
  StageScratch scratch_{2};  // acceleration, midpoint velocity
};

}  // namespace tickfx
