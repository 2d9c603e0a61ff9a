#include "integrators/SemiImplicitEuler.h"

#include "integrators/CheckedRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// One row: v ← v + a·dt, then p ← p + v_new·dt. Returns the new position, the one value the check
// needs: p_new = p + v_new·dt with dt > 0 is non-finite whenever p or v_new is, or when it
// overflows.
inline float semiImplicitEulerRow(float dt, float acceleration, Eigen::Index i, float* pos,
                                  float* vel, float* last) {
  const float position = pos[i];
  const float velocity = vel[i] + acceleration * dt;
  const float next = position + velocity * dt;
  last[i] = position;
  vel[i] = velocity;
  pos[i] = next;
  return next;
}

}  // namespace

void SemiImplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  if (const auto forms = tickForms(pool, forces, time, {0})) {
    runStateUpdateUnderForms(pool, scratch_, rows, check, *forms, [dt](const auto& a) {
      return [dt, a](Eigen::Index i, float* pos, float* vel, float* last) {
        return semiImplicitEulerRow(dt, a.at(0, vel[i]), i, pos, vel, last);
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
           return semiImplicitEulerRow(dt, acc[i], i, pos, vel, last);
         };
         updateTile(check, pool, tile.rows(), update, [&](int c) {
           return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                             static_cast<const float*>(a[c].data()));
         });
       }});
}

}  // namespace tickfx
