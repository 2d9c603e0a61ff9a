#include "integrators/SemiImplicitEuler.h"

#include "integrators/SingleEvaluationStep.h"

namespace tickfx {
namespace {

// The rows `at`: v ← v + a·dt, then p ← p + v_new·dt. Returns the new position, the one value
// the check needs: p_new = p + v_new·dt with dt > 0 is non-finite whenever p or v_new is, or when
// it overflows.
template <class At, class Lane>
Lane semiImplicitEulerRow(float dt, Lane acceleration, At at, float* pos, float* vel, float* last) {
  const Lane position = at.load(pos);
  const Lane velocity = at.load(vel) + acceleration * dt;
  const Lane next = position + velocity * dt;
  at.copy(last, position);
  at.store(vel, velocity);
  at.store(pos, next);
  return next;
}

// The row kernel as stepSingleEvaluation() takes it.
auto rowOf(float dt) {
  return [dt](auto acceleration, auto at, float* pos, float* vel, float* last) {
    return semiImplicitEulerRow(dt, acceleration, at, pos, vel, last);
  };
}

}  // namespace

void SemiImplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  const StepRows& rows, NonfiniteCheck* check) {
  stepSingleEvaluation(pool, forces, time, rows, check, scratch_, rowOf(time.dt()));
}

bool SemiImplicitEuler::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  StateBound& bound) const {
  return boundSingleEvaluation(pool, forces, time, rowOf(time.dt()), bound);
}

}  // namespace tickfx
