#include "integrators/SemiImplicitEuler.h"

#include <cmath>

namespace tickfx {

namespace {

// One component of the update over n rows, as one loop: the new position is still in a register
// when the non-finite check reads it, which is what makes the check nearly free (a separate pass
// re-reading the tile cost 11 % of this tick at 10⁴ particles, and a per-row test of the exponent
// bits inside this loop still 8 %).
//
// The check is a sum of the new positions in kLanes independent partial sums (so the compiler
// vectorises it without reassociating anything, which -ffast-math is banned for): a sum with a
// NaN or an infinity among its terms is not finite, whatever its order, so a finite sum clears
// every row. A sum can also overflow from finite terms; then the caller's exact per-row scan finds
// nothing, and only time is lost. Testing the new position alone is exact: p_new = p + v_new·dt
// with dt > 0, so a non-finite p or v_new gives a non-finite p_new, and p_new can only be
// non-finite by one of those or by overflowing.
//
// The state's arithmetic is the same with and without the check. Returns whether some p_new may
// be non-finite (always false without kCheck).
//
// Not inlined: called from integrate()'s lambda, the loop loses __restrict (the lambda's captures
// may alias) and is versioned for aliasing, and the two instantiations were placed so differently
// that the checked tick measured 4 to 9 % slower than the unchecked one; as functions of their own
// they measure the same (tick_bench, 10⁴ particles).
template <bool kCheck>
[[gnu::noinline]] bool updateComponent(float* __restrict p, float* __restrict v,
                                       float* __restrict old, const float* __restrict a,
                                       Eigen::Index n, float dt) {
  const auto row = [&](Eigen::Index i) {
    const float position = p[i];
    const float velocity = v[i] + a[i] * dt;
    const float next = position + velocity * dt;
    old[i] = position;
    v[i] = velocity;
    p[i] = next;
    return next;
  };
  constexpr int kLanes = 8;
  float sums[kLanes] = {};
  Eigen::Index i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int lane = 0; lane < kLanes; ++lane) {
      const float next = row(i + lane);
      if constexpr (kCheck) sums[lane] += next;
    }
  }
  for (; i < n; ++i) {
    const float next = row(i);
    if constexpr (kCheck) sums[0] += next;
  }
  if constexpr (!kCheck) return false;
  float total = 0.0f;
  for (const float sum : sums) total += sum;
  return !std::isfinite(total);
}

}  // namespace

void SemiImplicitEuler::integrate(ParticlePool& pool, const ForceSet& forces,
                                  const StepTime& time) {
  const float dt = time.dt();
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  Vec3Column& prev = pool.previousPosition();
  const TickInstant t0 = time.stage(0);
  NonfiniteCheck* const check = nonfiniteCheck();
  runPasses(pool.size(), forces.isLocal(), scratch_,
            {forcePass(pool, forces, kPoolColumn, kPoolColumn, t0, 0), [&](const Tile& tile) {
               Vec3Rows a = tile.stage(0), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                        old = rowsOf(prev, tile.rows());
               const Eigen::Index n = pr.x.size();
               bool suspect = false;
               for (int c = 0; c < 3; ++c) {
                 if (check != nullptr) {
                   suspect |= updateComponent<true>(pr[c].data(), vr[c].data(), old[c].data(),
                                                    a[c].data(), n, dt);
                 } else {
                   updateComponent<false>(pr[c].data(), vr[c].data(), old[c].data(), a[c].data(), n,
                                          dt);
                 }
               }
               // The exact per-row test, which flags the rows, only for a tile that has some.
               if (suspect) check->scan(pool, tile.rows().begin, tile.rows().end);
             }});
}

}  // namespace tickfx
