// Velocity Verlet: second order, symplectic, keeps the acceleration between ticks.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// p ← p + v·dt + a·dt²/2; a_new = a(p_new, v + a·dt, t + dt); v ← v + (a + a_new)·dt/2.
/// The acceleration is stored in pool.acceleration() for the next tick, so a step costs one force
/// evaluation (two in a particle's first tick). Velocity-dependent forces see the predicted
/// velocity v + a·dt at the end of the step.
class VelocityVerlet final : public Integrator {
 public:
  std::string_view name() const override { return "velocity_verlet"; }
  int order() const override { return 2; }
  int evaluationsPerStep() const override { return 1; }
  bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 StateBound& bound) const override;
  bool boundSpawned(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                    StateBound& bound) const override;
  AdvectionScheme advectionScheme() const override { return AdvectionScheme::Heun; }

 protected:
  void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 const StepRows& rows, NonfiniteCheck* check) override;
  void prepareColumns(ParticlePool& pool) const override { pool.keepAcceleration(); }

 private:
  StageScratch scratch_{2};  // predicted velocity, new acceleration
};

}  // namespace tickfx
