#include "integrators/VelocityVerlet.h"

#include "integrators/CheckedRows.h"
#include "integrators/MagnitudeRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// The one pass's kernel under the forms' `accelerations`: the position, the predicted velocity,
// a(t + dt) from it and the new velocity in the row's registers (the position does not enter a
// uniform force or a drag).
auto underForms(float dt) {
  const float halfDt = 0.5f * dt;
  const float halfDt2 = 0.5f * dt * dt;
  return [=](const auto& accelerations) {
    return [=](auto row, float* pos, float* vel, float* last, float* acc) {
      const auto position = row.load(pos);
      const auto velocity = row.load(vel);
      const auto acceleration = row.load(acc);
      const auto next = position + (velocity * dt + acceleration * halfDt2);
      const auto accNext = accelerations.at(2, velocity + acceleration * dt);
      const auto nextV = velocity + (acceleration + accNext) * halfDt;
      row.copy(last, position);
      row.store(pos, next);
      row.store(vel, nextV);
      row.store(acc, accNext);
      return CheckedPair{next, nextV};  // the new velocity is not in next
    };
  };
}

// The tick's forms at the stages its one pass reads: t + dt (a(t) is the one kept from the tick
// before). integrate() and boundTick() both ask here, so the bound runs on the forms the tick runs
// on.
std::optional<TickForms> velocityVerletForms(ParticlePool& pool, const ForceSet& forces,
                                             const StepTime& time) {
  return tickForms(pool, forces, time, {2});
}

}  // namespace

bool VelocityVerlet::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                               StateBound& bound) const {
  const auto forms = velocityVerletForms(pool, forces, time);
  if (!forms) return false;
  bound = boundTickUnderForms(*forms, underForms(time.dt()), bound, ExtraColumn::kFourth);
  return true;
}

// A spawned row starts with a(t) (startRows in integrate()): under the forms, the forms' own.
bool VelocityVerlet::boundSpawned(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  StateBound& bound) const {
  const auto forms = tickForms(pool, forces, time, {0});
  if (!forms) return false;
  boundSpawnedUnderForms(
      *forms, [](const auto& a, Magnitude, Magnitude velocity) { return a.at(0, velocity); },
      bound);
  return true;
}

void VelocityVerlet::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                               const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  const float halfDt = 0.5f * dt;
  const float halfDt2 = 0.5f * dt * dt;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& a = pool.acceleration();
  const std::size_t fresh = rows.fresh;
  const std::size_t n = rows.rows.end;
  const TickInstant t0 = time.stage(0), t1 = time.stage(2);
  // Stepped rows carry a(t) from their last tick; new rows need it evaluated.
  const auto startRows = [&](const Tile& tile) {
    const RowRange started = intersect(tile.rows(), fresh, n);
    if (started.count() == 0) return;
    Vec3Rows out = rowsOf(a, started);
    forces.evaluate({pool, Vec3View::of(p), Vec3View::of(v), t0}, started, out);
  };
  if (const auto forms = velocityVerletForms(pool, forces, time)) {
    runOnePass(pool, scratch_, rows, check, *forms, underForms(dt), startRows, a);
    return;
  }
  const TileCheck tiles = forcePassCheck(check, pool, forces, rows);
  runPasses(
      rows, forces.isLocal(), scratch_,
      {startRows,
       [&](const Tile& tile) {
         Vec3Rows vPred = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                  ar = rowsOf(a, tile.rows()), old = previousRowsOf(pool, rows, tile.rows());
         // The position is final here: it is checked as it is written.
         const auto update = [dt, halfDt2](auto at, float* pos, float* last, float* pred,
                                           const float* vel, const float* acc) {
           const auto position = at.load(pos);
           const auto velocity = at.load(vel);
           const auto acceleration = at.load(acc);
           const auto next = position + (velocity * dt + acceleration * halfDt2);
           at.copy(last, position);
           at.store(pos, next);
           at.store(pred, velocity + acceleration * dt);
           return next;
         };
         // The velocity is still the tick's start (finite), so the scan flags the rows
         // whose new position is not; the last pass adds those whose new velocity is not.
         updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
           return std::tuple(pr[c].data(), old[c].data(), vPred[c].data(),
                             static_cast<const float*>(vr[c].data()),
                             static_cast<const float*>(ar[c].data()));
         });
       },
       forcePass(pool, forces, kPoolColumn, 0, t1, 1),
       [&](const Tile& tile) {
         Vec3Rows aNew = tile.stage(1), vr = rowsOf(v, tile.rows()), ar = rowsOf(a, tile.rows());
         // The new velocity alone: the position was checked by the first update.
         const auto update = [halfDt](auto at, float* vel, float* acc, const float* accNext) {
           const auto next = at.load(accNext);
           const auto velocity = at.load(vel) + (at.load(acc) + next) * halfDt;
           at.store(vel, velocity);
           at.store(acc, next);
           return velocity;
         };
         updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
           return std::tuple(vr[c].data(), ar[c].data(), static_cast<const float*>(aNew[c].data()));
         });
       }},
      tiles.afterEachTile);
}

}  // namespace tickfx
