// The tick of a scheme that evaluates the forces once, at t, from the state at t, and then
// updates each row from its own position, velocity and that acceleration (explicit and
// semi-implicit Euler): the one pass under uniform forces and a drag, else a force pass and an
// update pass.
#pragma once

#include <tuple>

#include "integrators/CheckedRows.h"
#include "integrators/Integrator.h"
#include "integrators/MagnitudeRows.h"
#include "integrators/StagePasses.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {

/// The one pass's kernel of `row` under the forms' accelerations `a` (see runOnePass).
template <class Row>
auto singleEvaluationUnderForms(const Row& row) {
  return [&row](const auto& a) {
    return [row, a](auto at, float* pos, float* vel, float* last) {
      return row(a.at(0, at.load(vel)), at, pos, vel, last);
    };
  };
}

/// The tick's forms at the one stage such a scheme reads, t: stepSingleEvaluation() and
/// boundSingleEvaluation() both ask here, so the bound runs on the forms the tick runs on.
inline std::optional<TickForms> singleEvaluationForms(ParticlePool& pool, const ForceSet& forces,
                                                      const StepTime& time) {
  return tickForms(pool, forces, time, {0});
}

/// Integrator::boundTick() of a scheme whose row is `row` (see stepSingleEvaluation).
template <class Row>
bool boundSingleEvaluation(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                           const Row& row, StateBound& bound) {
  const auto forms = singleEvaluationForms(pool, forces, time);
  if (!forms) return false;
  bound = boundTickUnderForms(*forms, singleEvaluationUnderForms(row), bound);
  return true;
}

/// Advances `rows` one tick: `row(acceleration, at, pos, vel, last)` updates the rows `at` (a
/// RowsAt) of one component (acceleration in m/s², a value of at's lane type; the columns as
/// updateRowsAs passes them) and returns what the check sums. `scratch` holds the acceleration
/// of the force pass (one stage value).
template <class Row>
void stepSingleEvaluation(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                          const StepRows& rows, NonfiniteCheck* check, StageScratch& scratch,
                          const Row& row) {
  if (const auto forms = singleEvaluationForms(pool, forces, time)) {
    runStateUpdateUnderForms(pool, scratch, rows, check, *forms, singleEvaluationUnderForms(row));
    return;
  }
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  const TileCheck tiles = forcePassCheck(check, pool, forces, rows);
  runPasses(rows, forces.isLocal(), scratch,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, time.stage(0), 0),
             [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                        old = previousRowsOf(pool, rows, tile.rows());
               const auto update = [row](auto at, float* pos, float* vel, float* last,
                                         const float* acc) {
                 return row(at.load(acc), at, pos, vel, last);
               };
               updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
                 return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                                   static_cast<const float*>(a[c].data()));
               });
             }},
            tiles.afterEachTile);
}

}  // namespace tickfx
