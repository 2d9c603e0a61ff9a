#include "integrators/ExplicitEuler.h"

#include "integrators/SingleEvaluationStep.h"

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
  stepSingleEvaluation(
      pool, forces, time, rows, check, scratch_,
      [dt](float acceleration, Eigen::Index i, float* pos, float* vel, float* last) {
        return explicitEulerRow(dt, acceleration, i, pos, vel, last);
      });
}

}  // namespace tickfx
