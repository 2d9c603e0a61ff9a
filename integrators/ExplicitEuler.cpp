#include "integrators/ExplicitEuler.h"

#include "integrators/CheckedRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// One row: p ← p + v·dt and v ← v + a·dt, both from the state at t. Returns what the check sums:
// the new position plus the new velocity, as the new velocity is not in the new position.
inline float explicitEulerRow(float dt, float acceleration, Eigen::Index i, float* pos, float* vel,
                              float* last) {
  const float position = pos[i];
  const float velocity = vel[i];
  const float nextP = position + velocity * dt;
  const float nextV = velocity + acceleration * dt;
  last[i] = position;
  pos[i] = nextP;
  vel[i] = nextV;
  return nextP + nextV;
}

}  // namespace

void ExplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                              const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  if (const auto forms = tickForms(pool, forces, time, {0})) {
    runStateUpdateUnderForms(pool, scratch_, rows, check, *forms, [dt](const auto& a) {
      return [dt, a](Eigen::Index i, float* pos, float* vel, float* last) {
        return explicitEulerRow(dt, a.at(0, vel[i]), i, pos, vel, last);
      };
    });
    return;
  }
  runPasses(
      rows, forces.isLocal(), scratch_,
      {forcePass(pool, forces, kPoolColumn, kPoolColumn, time.stage(0), 0), [&](const Tile& tile) {
         Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                  old = rowsOf(prev, tile.rows());
         const auto update = [dt](Eigen::Index i, float* pos, float* vel, float* last,
                                  const float* acc) {
           return explicitEulerRow(dt, acc[i], i, pos, vel, last);
         };
         updateTile(check, pool, tile.rows(), update, [&](int c) {
           return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                             static_cast<const float*>(a[c].data()));
         });
       }});
}

}  // namespace tickfx
