#include "integrators/Midpoint.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void Midpoint::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                         const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0), tHalf = time.stage(1);
  runPasses(rows, forces.isLocal(), scratch_,
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
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows());
               bool suspect = false;
               // The position is final since the first update; it is checked here, with the new
               // velocity, from cache.
               const auto update = [dt](Eigen::Index i, const float* pos, float* vel,
                                        const float* acc) {
                 const float velocity = vel[i] + acc[i] * dt;
                 vel[i] = velocity;
                 return pos[i] + velocity;
               };
               for (int c = 0; c < 3; ++c) {
                 suspect |=
                     updateRows(check, vr.x.size(), update, static_cast<const float*>(pr[c].data()),
                                vr[c].data(), static_cast<const float*>(a[c].data()));
               }
               if (suspect) check->scan(pool, tile.rows().begin, tile.rows().end);
             }});
}

}  // namespace tickfx
