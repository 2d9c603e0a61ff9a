#include "integrators/ExplicitEuler.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void ExplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                              const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0);
  runPasses(rows, forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0), [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                        old = rowsOf(prev, tile.rows());
               const auto update = [dt](Eigen::Index i, float* pos, float* vel, float* last,
                                        const float* acc) {
                 const float position = pos[i];
                 const float velocity = vel[i];
                 const float nextP = position + velocity * dt;
                 const float nextV = velocity + acc[i] * dt;
                 last[i] = position;
                 pos[i] = nextP;
                 vel[i] = nextV;
                 return nextP + nextV;  // the new velocity is not in the new position
               };
               updateTile(check, pool, tile.rows(), update, [&](int c) {
                 return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                                   static_cast<const float*>(a[c].data()));
               });
             }});
}

}  // namespace tickfx
