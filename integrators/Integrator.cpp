#include "integrators/Integrator.h"

namespace tickfx {

Integrator::Integrator() = default;
Integrator::~Integrator() = default;

void Integrator::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  if (!forces.prescribesVelocity()) {
    integrate(pool, forces, time);
    return;
  }
  if (!advection_) advection_ = std::make_unique<Advection>(advectionScheme());
  advection_->step(pool, forces, time);
}

}  // namespace tickfx
