#include "integrators/SemiImplicitEuler.h"

#include "integrators/CheckedRows.h"

namespace tickfx {

void SemiImplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                                  const StepRows& rows, NonfiniteCheck* check) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0);
  if (const auto form = forces.uniformAndDrag({pool, Vec3View::of(p), Vec3View::of(v), t0})) {
    integrateUniformAndDrag(pool, *form, dt, rows, check);
    return;
  }
  runPasses(rows, forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0), [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                        old = rowsOf(prev, tile.rows());
               // The new position alone is tested, exactly: p_new = p + v_new·dt with dt > 0 is
               // non-finite whenever p or v_new is, or when it overflows.
               const auto update = [dt](Eigen::Index i, float* pos, float* vel, float* last,
                                        const float* acc) {
                 const float position = pos[i];
                 const float velocity = vel[i] + acc[i] * dt;
                 const float next = position + velocity * dt;
                 last[i] = position;
                 vel[i] = velocity;
                 pos[i] = next;
                 return next;
               };
               updateTile(check, pool, tile.rows(), update, [&](int c) {
                 return std::tuple(pr[c].data(), vr[c].data(), old[c].data(),
                                   static_cast<const float*>(a[c].data()));
               });
             }});
}

void SemiImplicitEuler::integrateUniformAndDrag(ParticlePool& pool,
                                                const ForceSet::UniformAndDrag& form, float dt,
                                                const StepRows& rows, NonfiniteCheck* check) {
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  // One pass, the acceleration formed in registers by ForceSet::evaluate()'s own operations
  // (the uniform sum, then + k·(air − v)): the bits of the two passes, without writing the
  // acceleration to a tile and reading it back.
  runPasses(rows, true, scratch_, {[&](const Tile& tile) {
              Vec3Rows pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                       old = rowsOf(prev, tile.rows());
              bool suspect = false;
              for (int c = 0; c < 3; ++c) {
                const float uniform = form.uniform[c], k = form.k, air = form.air[c];
                const auto step = [dt](float position, float velocity, float acceleration,
                                       float* vel, float* pos, float* last, Eigen::Index i) {
                  const float nextV = velocity + acceleration * dt;
                  const float next = position + nextV * dt;
                  last[i] = position;
                  vel[i] = nextV;
                  pos[i] = next;
                  return next;
                };
                const Eigen::Index n = pr.x.size();
                if (form.drag) {
                  suspect |= updateRows(
                      check, n,
                      [=](Eigen::Index i, float* pos, float* vel, float* last) {
                        return step(pos[i], vel[i], uniform + k * (air - vel[i]), vel, pos, last,
                                    i);
                      },
                      pr[c].data(), vr[c].data(), old[c].data());
                } else {
                  suspect |= updateRows(
                      check, n,
                      [=](Eigen::Index i, float* pos, float* vel, float* last) {
                        return step(pos[i], vel[i], uniform, vel, pos, last, i);
                      },
                      pr[c].data(), vr[c].data(), old[c].data());
                }
              }
              if (suspect) check->scan(pool, tile.rows().begin, tile.rows().end);
            }});
}

}  // namespace tickfx
