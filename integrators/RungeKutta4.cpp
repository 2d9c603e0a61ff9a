#include "integrators/RungeKutta4.h"

#include "integrators/StagePasses.h"

namespace tickfx {

void RungeKutta4::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time) {
  for (Vec3Column* c : {&k1_, &k2_, &k3_, &k4_, &p2_, &v2_, &p3_, &v3_, &p4_, &v4_}) {
    ensureRows(*c, pool.storageRows());
  }
  const float h = time.dt();
  const float halfH = 0.5f * h;
  const float sixthH = h / 6.0f;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const ForceInput s1{pool, p, v, time.at(0.0), time.tick};
  const ForceInput s2{pool, p2_, v2_, time.at(0.5), time.tick};
  const ForceInput s3{pool, p3_, v3_, time.at(0.5), time.tick};
  const ForceInput s4{pool, p4_, v4_, time.at(1.0), time.tick};
  runPasses(pool.size(), forces.isLocal(),
            {[&](RowRange r) { forces.evaluate(s1, r, k1_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(p2_[c], r) = rowsOf(p[c], r) + rowsOf(v[c], r) * halfH;
                 rowsOf(v2_[c], r) = rowsOf(v[c], r) + rowsOf(k1_[c], r) * halfH;
               }
             },
             [&](RowRange r) { forces.evaluate(s2, r, k2_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(p3_[c], r) = rowsOf(p[c], r) + rowsOf(v2_[c], r) * halfH;
                 rowsOf(v3_[c], r) = rowsOf(v[c], r) + rowsOf(k2_[c], r) * halfH;
               }
             },
             [&](RowRange r) { forces.evaluate(s3, r, k3_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(p4_[c], r) = rowsOf(p[c], r) + rowsOf(v3_[c], r) * h;
                 rowsOf(v4_[c], r) = rowsOf(v[c], r) + rowsOf(k3_[c], r) * h;
               }
             },
             [&](RowRange r) { forces.evaluate(s4, r, k4_); },
             [&](RowRange r) {
               for (int c = 0; c < 3; ++c) {
                 rowsOf(prev[c], r) = rowsOf(p[c], r);
                 rowsOf(p[c], r) += ((rowsOf(v[c], r) + rowsOf(v2_[c], r) * 2.0f) +
                                     (rowsOf(v3_[c], r) * 2.0f + rowsOf(v4_[c], r))) * sixthH;
                 rowsOf(v[c], r) += ((rowsOf(k1_[c], r) + rowsOf(k2_[c], r) * 2.0f) +
                                     (rowsOf(k3_[c], r) * 2.0f + rowsOf(k4_[c], r))) * sixthH;
               }
             }});
}

}  // namespace tickfx
