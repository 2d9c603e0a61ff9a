#include "integrators/Integrator.h"

#include "integrators/Advection.h"

namespace tickfx {

Integrator::Integrator() = default;
Integrator::~Integrator() = default;

void Integrator::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                      NonfiniteCheck* check, bool keepPrevious) {
  prepare(pool, forces);
  if (keepPrevious) pool.keepPrevious();
  stepRows(pool, forces, time, StepRows::wholePool(pool, keepPrevious), check);
}

bool Integrator::boundTick(ParticlePool& /*pool*/, const ForceSet& /*forces*/,
                           const StepTime& /*time*/, StateBound& /*bound*/) const {
  return false;
}

bool Integrator::boundSpawned(ParticlePool& /*pool*/, const ForceSet& /*forces*/,
                              const StepTime& /*time*/, StateBound& /*bound*/) const {
  return true;
}

void Integrator::prepare(ParticlePool& pool, const ForceSet& forces) {
  prepareColumns(pool);
  if (readsPreviousPosition()) pool.keepPrevious(true);
  if (forces.prescribesVelocity() && !advection_) {
    advection_ = std::make_unique<Advection>(advectionScheme());
  }
}

void Integrator::stepRows(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                          const StepRows& rows, NonfiniteCheck* check) {
  if (!forces.prescribesVelocity()) {
    integrate(pool, forces, time, rows, check);
    return;
  }
  TICKFX_ASSERT(advection_ != nullptr, "an advected step before prepare()");
  // The advection schemes check each tile once their passes are done with it.
  RowPass scan;
  if (check != nullptr) {
    scan = [check, &pool](const Tile& tile) {
      check->scan(pool, tile.rows().begin, tile.rows().end);
    };
  }
  advection_->step(pool, forces, time, rows, scan);
}

}  // namespace tickfx
