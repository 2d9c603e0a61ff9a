#include "integrators/SemiImplicitEuler.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void SemiImplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
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
               bool suspect = false;
               // The new position alone is tested, exactly: p_new = p + v_new·dt with dt > 0 is
               // non-finite whenever p or v_new is, or when it overflows.
               const auto update = [dt](Eigen::Index i, float* pos, float* vel, float* last,
                                        const float* acc) {
                 const float position = pos[i];
                 const float velocity = vel[i] + acc[i] * dt;
                 const float next = position + velocity * dt;
                 last[i] = position;
                 vel[i] = velocity;
                 pos[i] = next;
                 return next;
               };
               for (int c = 0; c < 3; ++c) {
                 suspect |= updateRows(check, pr.x.size(), update, pr[c].data(), vr[c].data(),
                                       old[c].data(), a[c].data());
               }
               // The exact per-row test, which flags the rows, only for a tile that has some.
               if (suspect) check->scan(pool, tile.rows().begin, tile.rows().end);
             }});
}

}  // namespace tickfx
