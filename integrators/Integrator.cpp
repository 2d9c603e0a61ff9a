#include "integrators/Integrator.h"

namespace tickfx {

Integrator::Integrator() = default;
Integrator::~Integrator() = default;

void Integrator::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                      NonfiniteCheck* check) {
  check_ = check;
  if (!forces.prescribesVelocity()) {
    integrate(pool, forces, time);
  } else {
    if (!advection_) advection_ = std::make_unique<Advection>(advectionScheme());
    advection_->step(pool, forces, time, afterEachTile(pool));
  }
  check_ = nullptr;
}

RowPass Integrator::afterEachTile(ParticlePool& pool) const {
  if (check_ == nullptr) return {};
  return [check = check_, &pool](const Tile& tile) {
    check->scan(pool, tile.rows().begin, tile.rows().end);
  };
}

}  // namespace tickfx
