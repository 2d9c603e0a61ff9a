#include "integrators/SemiImplicitEuler.h"

#include "integrators/SingleEvaluationStep.h"

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
  stepSingleEvaluation(
      pool, forces, time, rows, check, scratch_,
      [dt](float acceleration, Eigen::Index i, float* pos, float* vel, float* last) {
        return semiImplicitEulerRow(dt, acceleration, i, pos, vel, last);
      });
}

}  // namespace tickfx
