#include "integrators/VelocityVerlet.h"

namespace tickfx {

void VelocityVerlet::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  const float halfDt2 = 0.5f * dt * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& a = pool.acceleration();
  Vec3Column& prev = pool.previousPosition();
  const std::size_t fresh = pool.firstUnstepped();
  const std::size_t n = pool.size();
  const TickInstant t0 = time.stage(0), t1 = time.stage(2);
  runPasses(
      n, forces.isLocal(), scratch_,
      {[&](const Tile& tile) {
         // Stepped rows carry a(t) from their last tick; new rows need it evaluated.
         const RowRange started = intersect(tile.rows(), fresh, n);
         if (started.count() == 0) return;
         Vec3Rows out = rowsOf(a, started);
         forces.evaluate({pool, Vec3View::of(p), Vec3View::of(v), t0}, started, out);
       },
       [&](const Tile& tile) {
         Vec3Rows vPred = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                  ar = rowsOf(a, tile.rows()), old = rowsOf(prev, tile.rows());
         for (int c = 0; c < 3; ++c) {
           old[c] = pr[c];
           pr[c] += vr[c] * dt + ar[c] * halfDt2;
           vPred[c] = vr[c] + ar[c] * dt;
         }
       },
       forcePass(pool, forces, kPoolColumn, 0, t1, 1),
       [&](const Tile& tile) {
         Vec3Rows aNew = tile.stage(1), vr = rowsOf(v, tile.rows()), ar = rowsOf(a, tile.rows());
         for (int c = 0; c < 3; ++c) {
           vr[c] += (ar[c] + aNew[c]) * halfDt;
           ar[c] = aNew[c];
         }
       }},
      afterEachTile(pool));
}

}  // namespace tickfx
