#include "integrators/SemiImplicitEuler.h"

#include "integrators/StagePasses.h"

namespace tickfx {

void SemiImplicitEuler::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  ensureRows(accel_, pool.storageRows());
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const ForceInput in{pool, p, v, time.at(0.0), time.tick};
  runPasses(pool.size(), forces.isLocal(),
            {[&](RowRange r) { forces.evaluate(in, r, accel_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(prev[c], r) = rowsOf(p[c], r);
                 rowsOf(v[c], r) += rowsOf(accel_[c], r) * dt;
                 rowsOf(p[c], r) += rowsOf(v[c], r) * dt;
               }
             }});
}

}  // namespace tickfx
