#include "integrators/Midpoint.h"

namespace tickfx {

void Midpoint::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0), tHalf = time.stage(1);
  runPasses(pool.size(), forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), vMid = tile.stage(1), pr = rowsOf(p, tile.rows()),
                        vr = rowsOf(v, tile.rows()), old = rowsOf(prev, tile.rows());
               for (int c = 0; c < 3; ++c) {
                 old[c] = pr[c];
                 vMid[c] = vr[c] + a[c] * halfDt;
                 pr[c] += vMid[c] * dt;
               }
             },
             // The second evaluation sees the new position (where a field would be sampled) with
             // the midpoint velocity, at t + dt/2.
             forcePass(pool, forces, kPoolColumn, 1, tHalf, 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), vr = rowsOf(v, tile.rows());
               for (int c = 0; c < 3; ++c) vr[c] += a[c] * dt;
             }},
            afterEachTile(pool));
}

}  // namespace tickfx
