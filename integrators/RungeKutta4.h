// The classic fourth-order Runge–Kutta method.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// Four evaluations per tick, at t, t + dt/2 (twice) and t + dt, combined with weights
/// 1/6, 1/3, 1/3, 1/6. Fourth order; slowly loses oscillator energy (not symplectic).
class RungeKutta4 final : public Integrator {
 public:
  std::string_view name() const override { return "rk4"; }
  int order() const override { return 4; }
  int evaluationsPerStep() const override { return 4; }
  bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 StateBound& bound) const override;
  AdvectionScheme advectionScheme() const override { return AdvectionScheme::RungeKutta4; }

 protected:
  void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 const StepRows& rows, NonfiniteCheck* check) override;

 private:
  StageScratch scratch_{10};  // k1..k4, then the stage states p2 v2 p3 v3 p4 v4
};

}  // namespace tickfx
