#include "integrators/PositionVerlet.h"

#include "integrators/CheckedRows.h"
#include "integrators/MagnitudeRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// A new particle has no history: the position it would have had a step ago, p − v·dt + a·dt²/2.
template <class Lane>
Lane startingPrevious(Lane position, Lane velocity, Lane acceleration, float dt, float halfDt2) {
  return position - velocity * dt + acceleration * halfDt2;
}

// One row: p_new = 2p − p_prev + a·dt², v = (p_new − p)/dt. Returns the velocity, which alone
// tells: it is not finite when the new position is not (the old one passed last tick's check),
// and it can overflow where both positions are finite.
template <class At, class Lane>
Lane positionVerletRow(float dt2, float invDt, Lane acceleration, At at, float* pos, float* vel,
                       float* last) {
  const Lane position = at.load(pos);
  const Lane next = (position * 2.0f - at.load(last)) + acceleration * dt2;
  const Lane velocity = (next - position) * invDt;
  at.copy(last, position);
  at.store(pos, next);
  at.store(vel, velocity);
  return velocity;
}

// The one pass's kernel under the forms' accelerations `a`.
auto underForms(float dt2, float invDt) {
  return [dt2, invDt](const auto& a) {
    return [dt2, invDt, a](auto at, float* pos, float* vel, float* last) {
      return positionVerletRow(dt2, invDt, a.at(0, at.load(vel)), at, pos, vel, last);
    };
  };
}

// The tick's forms at the stages its one pass reads: t. integrate(), boundTick() and boundSpawned()
// all ask here, so the bound runs on the forms the tick runs on.
std::optional<TickForms> positionVerletForms(ParticlePool& pool, const ForceSet& forces,
                                             const StepTime& time) {
  return tickForms(pool, forces, time, {0});
}

}  // namespace

bool PositionVerlet::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                               StateBound& bound) const {
  const auto forms = positionVerletForms(pool, forces, time);
  if (!forms) return false;
  const float dt = time.dt();
  bound = boundTickUnderForms(*forms, underForms(dt * dt, static_cast<float>(time.stepRateHz)),
                              bound, ExtraColumn::kPrevious);
  return true;
}

bool PositionVerlet::boundSpawned(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  StateBound& bound) const {
  const auto forms = positionVerletForms(pool, forces, time);
  if (!forms) return false;
  const float dt = time.dt();
  const float halfDt2 = 0.5f * (dt * dt);
  boundSpawnedUnderForms(
      *forms,
      [dt, halfDt2](const auto& a, Magnitude position, Magnitude velocity) {
        return startingPrevious(position, velocity, a.at(0, velocity), dt, halfDt2);
      },
      bound);
  return true;
}

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
  // Component c of the rows of tile rows `r` spawned this tick: their history, with
  // `acceleration(i, v)` the acceleration of the tile's row i at velocity v.
  const auto start = [&](const RowRange& r, int c, const auto& acceleration) {
    const RowRange started = intersect(r, fresh, n);
    if (started.count() == 0) return;
    const auto offset = static_cast<Eigen::Index>(started.begin - r.begin);
    Vec3Rows old = rowsOf(prev, started), pr = rowsOf(p, started), vr = rowsOf(v, started);
    for (Eigen::Index i = 0; i < started.count(); ++i) {
      old[c][i] =
          startingPrevious(pr[c][i], vr[c][i], acceleration(offset + i, vr[c][i]), dt, halfDt2);
    }
  };
  if (const auto forms = positionVerletForms(pool, forces, time)) {
    const auto startTile = [&](const Tile& tile) {
      for (int c = 0; c < 3; ++c) {
        withFormAccelerations(*forms, c, [&](const auto& a) {
          start(tile.rows(), c, [&a](Eigen::Index, float velocity) { return a.at(0, velocity); });
        });
      }
    };
    runOnePass(pool, scratch_, rows, check, *forms, underForms(dt2, invDt), startTile);
    return;
  }
  const TileCheck tiles = forcePassCheck(check, pool, forces, rows);
  runPasses(rows, forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, time.stage(0), 0),
             [&](const Tile& tile) {
               const RowRange r = tile.rows();
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, r), vr = rowsOf(v, r),
                        old = rowsOf(prev, r);
               for (int c = 0; c < 3; ++c)
                 start(r, c, [&](Eigen::Index i, float) { return a[c][i]; });
               const auto update = [dt2, invDt](auto at, float* pos, float* vel, float* last,
                                                const float* acc) {
                 return positionVerletRow(dt2, invDt, at.load(acc), at, pos, vel, last);
               };
               updateTile(tiles.sums, pool, r, update, [&](int c) {
                 return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                                   static_cast<const float*>(a[c].data()));
               });
             }},
            tiles.afterEachTile);
}

}  // namespace tickfx
