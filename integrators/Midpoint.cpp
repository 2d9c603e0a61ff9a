#include "integrators/Midpoint.h"

#include "integrators/StagePasses.h"

namespace tickfx {

void Midpoint::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  ensureRows(accel_, pool.storageRows());
  ensureRows(midVelocity_, pool.storageRows());
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const ForceInput start{pool, p, v, time.at(0.0), time.tick};
  // The second evaluation sees the new position (where a field would be sampled) at t + dt/2.
  const ForceInput mid{pool, p, midVelocity_, time.at(0.5), time.tick};
  runPasses(pool.size(), forces.isLocal(),
            {[&](RowRange r) { forces.evaluate(start, r, accel_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(prev[c], r) = rowsOf(p[c], r);
                 rowsOf(midVelocity_[c], r) = rowsOf(v[c], r) + rowsOf(accel_[c], r) * halfDt;
                 rowsOf(p[c], r) += rowsOf(midVelocity_[c], r) * dt;
               }
             },
             [&](RowRange r) { forces.evaluate(mid, r, accel_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) rowsOf(v[c], r) += rowsOf(accel_[c], r) * dt;
             }});
}

}  // namespace tickfx
