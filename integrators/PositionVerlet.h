// Position (Störmer) Verlet: second order, velocity derived from positions.
#pragma once

#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// p_new = 2p − p_prev + a(p, v, t)·dt², v = (p_new − p)/dt. The pool's previous-position column
/// is the history; a particle in its first tick is started with p_prev = p − v·dt + a·dt²/2, which
/// makes the first step p + v·dt + a·dt²/2 (exact for constant acceleration). The velocity is a
/// backward difference, first order, and it lags half a step.
///
/// Precision: the velocity lives only in p − p_prev, and a·dt² is added to a position. In float,
/// when a·dt² falls below the spacing of floats at |p| (at 1000 Hz, 9.8e-6 m against 3.1e-5 m
/// at 490 m) the motion is quantised: after 10 s of free fall at 1000 Hz the error is metres.
/// Prefer velocity Verlet for small steps far from the origin.
class PositionVerlet final : public Integrator {
 public:
  std::string_view name() const override { return "position_verlet"; }
  int order() const override { return 2; }
  int evaluationsPerStep() const override { return 1; }
  bool readsPreviousPosition() const override { return true; }
  bool boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 StateBound& bound) const override;
  bool boundSpawned(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                    StateBound& bound) const override;
  AdvectionScheme advectionScheme() const override { return AdvectionScheme::Euler; }

 protected:
  void integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                 const StepRows& rows, NonfiniteCheck* check) override;

 private:
  StageScratch scratch_{1};  // acceleration
};

}  // namespace tickfx
