#include "integrators/Midpoint.h"

#include "integrators/CheckedRows.h"
#include "integrators/MagnitudeRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// The one pass's kernel under the forms' accelerations `a`: both evaluations in the row's
// registers, the midpoint velocity, then the acceleration at t + dt/2 from it (the position does
// not enter a uniform force or a drag).
auto underForms(float dt) {
  const float halfDt = 0.5f * dt;
  return [dt, halfDt](const auto& a) {
    return [dt, halfDt, a](auto at, float* pos, float* vel, float* last) {
      const auto position = at.load(pos);
      const auto velocity = at.load(vel);
      const auto mid = velocity + a.at(0, velocity) * halfDt;
      const auto next = position + mid * dt;
      const auto nextV = velocity + a.at(1, mid) * dt;
      at.copy(last, position);
      at.store(pos, next);
      at.store(vel, nextV);
      return CheckedPair{next, nextV};  // the new velocity is not in the new position
    };
  };
}

// The tick's forms at the stages its one pass reads: t and t + dt/2. integrate() and boundTick()
// both ask here, so the bound runs on the forms the tick runs on.
std::optional<TickForms> midpointForms(ParticlePool& pool, const ForceSet& forces,
                                       const StepTime& time) {
  return tickForms(pool, forces, time, {0, 1});
}

}  // namespace

bool Midpoint::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                         StateBound& bound) const {
  const auto forms = midpointForms(pool, forces, time);
  if (!forms) return false;
  bound = boundTickUnderForms(*forms, underForms(time.dt()), bound);
  return true;
}

void Midpoint::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                         const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  const TickInstant t0 = time.stage(0), tHalf = time.stage(1);
  if (const auto forms = midpointForms(pool, forces, time)) {
    runStateUpdateUnderForms(pool, scratch_, rows, check, *forms, underForms(dt));
    return;
  }
  const TileCheck tiles = forcePassCheck(check, pool, forces, rows);
  runPasses(rows, forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), vMid = tile.stage(1), pr = rowsOf(p, tile.rows()),
                        vr = rowsOf(v, tile.rows()), old = previousRowsOf(pool, rows, tile.rows());
               // The position is final here: it is checked as it is written.
               const auto update = [dt, halfDt](auto at, float* pos, float* last, float* mid,
                                                const float* vel, const float* acc) {
                 const auto position = at.load(pos);
                 const auto velocity = at.load(vel) + at.load(acc) * halfDt;
                 const auto next = position + velocity * dt;
                 at.copy(last, position);
                 at.store(mid, velocity);
                 at.store(pos, next);
                 return next;
               };
               // The velocity is still the tick's start (finite), so the scan flags the rows
               // whose new position is not; the last pass adds those whose new velocity is not.
               updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
                 return std::tuple(pr[c].data(), old[c].data(), vMid[c].data(),
                                   static_cast<const float*>(vr[c].data()),
                                   static_cast<const float*>(a[c].data()));
               });
             },
             // The second evaluation sees the new position (where a field would be sampled) with
             // the midpoint velocity, at t + dt/2.
             forcePass(pool, forces, kPoolColumn, 1, tHalf, 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), vr = rowsOf(v, tile.rows());
               // The new velocity alone: the position was checked by the first update.
               const auto update = [dt](auto at, float* vel, const float* acc) {
                 const auto velocity = at.load(vel) + at.load(acc) * dt;
                 at.store(vel, velocity);
                 return velocity;
               };
               updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
                 return std::tuple(vr[c].data(), static_cast<const float*>(a[c].data()));
               });
             }},
            tiles.afterEachTile);
}

}  // namespace tickfx
