#include "integrators/ExplicitEuler.h"

#include "integrators/SingleEvaluationStep.h"

namespace tickfx {
namespace {

// The rows `at`: p ← p + v·dt and v ← v + a·dt, both from the state at t. Returns both new
// values for the check, as the new velocity is not in the new position.
template <class At, class Lane>
CheckedPair<Lane> explicitEulerRow(float dt, Lane acceleration, At at, float* pos, float* vel,
                                   float* last) {
  const Lane position = at.load(pos);
  const Lane velocity = at.load(vel);
  const Lane nextP = position + velocity * dt;
  const Lane nextV = velocity + acceleration * dt;
  at.copy(last, position);
  at.store(pos, nextP);
  at.store(vel, nextV);
  return {nextP, nextV};
}

// The row kernel as stepSingleEvaluation() takes it.
auto rowOf(float dt) {
  return [dt](auto acceleration, auto at, float* pos, float* vel, float* last) {
    return explicitEulerRow(dt, acceleration, at, pos, vel, last);
  };
}

}  // namespace

void ExplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                              const StepRows& rows, NonfiniteCheck* check) {
  stepSingleEvaluation(pool, forces, time, rows, check, scratch_, rowOf(time.dt()));
}

bool ExplicitEuler::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                              StateBound& bound) const {
  return boundSingleEvaluation(pool, forces, time, rowOf(time.dt()), bound);
}

}  // namespace tickfx
