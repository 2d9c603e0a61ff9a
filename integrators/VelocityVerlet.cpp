#include "integrators/VelocityVerlet.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void VelocityVerlet::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                               const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  const float halfDt2 = 0.5f * dt * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& a = pool.acceleration();
  Vec3Column& prev = pool.previousPosition();
  const std::size_t fresh = rows.fresh;
  const std::size_t n = rows.rows.end;
  const TickInstant t0 = time.stage(0), t1 = time.stage(2);
  runPasses(rows, forces.isLocal(), scratch_,
            {[&](const Tile& tile) {
               // Stepped rows carry a(t) from their last tick; new rows need it evaluated.
               const RowRange started = intersect(tile.rows(), fresh, n);
               if (started.count() == 0) return;
               Vec3Rows out = rowsOf(a, started);
               forces.evaluate({pool, Vec3View::of(p), Vec3View::of(v), t0}, started, out);
             },
             [&](const Tile& tile) {
               Vec3Rows vPred = tile.stage(0), pr = rowsOf(p, tile.rows()),
                        vr = rowsOf(v, tile.rows()), ar = rowsOf(a, tile.rows()),
                        old = rowsOf(prev, tile.rows());
               for (int c = 0; c < 3; ++c) {
                 old[c] = pr[c];
                 pr[c] += vr[c] * dt + ar[c] * halfDt2;
                 vPred[c] = vr[c] + ar[c] * dt;
               }
             },
             forcePass(pool, forces, kPoolColumn, 0, t1, 1),
             [&](const Tile& tile) {
               Vec3Rows aNew = tile.stage(1), pr = rowsOf(p, tile.rows()),
                        vr = rowsOf(v, tile.rows()), ar = rowsOf(a, tile.rows());
               bool suspect = false;
               // The position is final since the first update; it is checked here, with the new
               // velocity, from cache.
               const auto update = [halfDt](Eigen::Index i, const float* pos, float* vel,
                                            float* acc, const float* accNext) {
                 const float velocity = vel[i] + (acc[i] + accNext[i]) * halfDt;
                 vel[i] = velocity;
                 acc[i] = accNext[i];
                 return pos[i] + velocity;
               };
               for (int c = 0; c < 3; ++c) {
                 suspect |= updateRows(check, vr.x.size(), update,
                                       static_cast<const float*>(pr[c].data()), vr[c].data(),
                                       ar[c].data(), static_cast<const float*>(aNew[c].data()));
               }
               if (suspect) check->scan(pool, tile.rows().begin, tile.rows().end);
             }});
}

}  // namespace tickfx
