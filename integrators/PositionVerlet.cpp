#include "integrators/PositionVerlet.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void PositionVerlet::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                               const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  const float dt2 = dt * dt;
  const float halfDt2 = 0.5f * dt2;
  const float invDt = static_cast<float>(time.stepRateHz);
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const std::size_t fresh = rows.fresh;
  const std::size_t n = rows.rows.end;
  const TickInstant t0 = time.stage(0);
  runPasses(
      rows, forces.isLocal(), scratch_,
      {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0), [&](const Tile& tile) {
         const RowRange r = tile.rows();
         // A new particle has no history: give it the position it would have had a step ago.
         const RowRange started = intersect(r, fresh, n);
         if (started.count() > 0) {
           const std::size_t i = started.begin - r.begin;
           Vec3Rows old = rowsOf(prev, started), pr = rowsOf(p, started), vr = rowsOf(v, started);
           Vec3Rows a = tile.stage(0);
           for (int c = 0; c < 3; ++c) {
             old[c] = pr[c] - vr[c] * dt +
                      a[c].segment(static_cast<Eigen::Index>(i), started.count()) * halfDt2;
           }
         }
         Vec3Rows a = tile.stage(0), pr = rowsOf(p, r), vr = rowsOf(v, r), old = rowsOf(prev, r);
         const auto update = [dt2, invDt](Eigen::Index i, float* pos, float* vel, float* last,
                                          const float* acc) {
           const float position = pos[i];
           const float next = (position * 2.0f - last[i]) + acc[i] * dt2;
           const float velocity = (next - position) * invDt;
           last[i] = position;
           pos[i] = next;
           vel[i] = velocity;
           // The velocity alone tells: it is not finite when the new position is not (the old one
           // passed last tick's check), and it can overflow where both positions are finite.
           return velocity;
         };
         updateTile(check, pool, r, update, [&](int c) {
           return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                             static_cast<const float*>(a[c].data()));
         });
       }});
}

}  // namespace tickfx
