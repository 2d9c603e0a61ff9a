#include "integrators/PositionVerlet.h"

#include "integrators/StagePasses.h"

namespace tickfx {

void PositionVerlet::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  ensureRows(accel_, pool.storageRows());
  const float dt = time.dt();
  const float dt2 = dt * dt;
  const float halfDt2 = 0.5f * dt2;
  const float invDt = static_cast<float>(static_cast<double>(time.stepRateHz));
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const std::size_t fresh = pool.firstUnstepped();
  const ForceInput in{pool, p, v, time.at(0.0), time.tick};
  runPasses(pool.size(), forces.isLocal(),
            {[&](RowRange r) { forces.evaluate(in, r, accel_); },
             [&](RowRange r) {
               // A new particle has no history: synthesise the position it would have had.
               const RowRange started = intersect(r, fresh, pool.size());
               for (int c = 0; c < 3; ++c) {
                 rowsOf(prev[c], started) = rowsOf(p[c], started) - rowsOf(v[c], started) * dt +
                                            rowsOf(accel_[c], started) * halfDt2;
               }
               for (int c = 0; c < 3; ++c) {
                 // v temporarily holds p_new so the update needs no extra column.
                 rowsOf(v[c], r) = (rowsOf(p[c], r) * 2.0f - rowsOf(prev[c], r)) + rowsOf(accel_[c], r) * dt2;
                 rowsOf(prev[c], r) = rowsOf(p[c], r);
                 rowsOf(p[c], r) = rowsOf(v[c], r);
                 rowsOf(v[c], r) = (rowsOf(p[c], r) - rowsOf(prev[c], r)) * invDt;
               }
             }});
}

}  // namespace tickfx
