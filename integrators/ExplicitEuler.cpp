#include "integrators/ExplicitEuler.h"

namespace tickfx {

void ExplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0);
  runPasses(pool.size(), forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                        old = rowsOf(prev, tile.rows());
               for (int c = 0; c < 3; ++c) {
                 old[c] = pr[c];
                 pr[c] += vr[c] * dt;
                 vr[c] += a[c] * dt;
               }
             }},
            afterEachTile(pool));
}

}  // namespace tickfx
