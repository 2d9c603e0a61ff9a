#include "integrators/VelocityVerlet.h"

#include "integrators/StagePasses.h"

namespace tickfx {

void VelocityVerlet::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  ensureRows(predictedVelocity_, pool.storageRows());
  ensureRows(newAccel_, pool.storageRows());
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  const float halfDt2 = 0.5f * dt * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& a = pool.acceleration();
  Vec3Column& prev = pool.previousPosition();
  const std::size_t fresh = pool.firstUnstepped();
  const ForceInput start{pool, p, v, time.at(0.0), time.tick};
  const ForceInput end{pool, p, predictedVelocity_, time.at(1.0), time.tick};
  runPasses(pool.size(), forces.isLocal(),
            {[&](RowRange r) {
               // Stepped rows carry a(t) from their last tick; new rows need it evaluated.
               const RowRange started = intersect(r, fresh, pool.size());
               if (started.count() > 0) forces.evaluate(start, started, a);
             },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(prev[c], r) = rowsOf(p[c], r);
                 rowsOf(p[c], r) += rowsOf(v[c], r) * dt + rowsOf(a[c], r) * halfDt2;
                 rowsOf(predictedVelocity_[c], r) = rowsOf(v[c], r) + rowsOf(a[c], r) * dt;
               }
             },
             [&](RowRange r) { forces.evaluate(end, r, newAccel_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(v[c], r) += (rowsOf(a[c], r) + rowsOf(newAccel_[c], r)) * halfDt;
                 rowsOf(a[c], r) = rowsOf(newAccel_[c], r);
               }
             }});
}

}  // namespace tickfx
