#include "integrators/RungeKutta4.h"

#include "integrators/CheckedRows.h"
#include "integrators/MagnitudeRows.h"
#include "integrators/UniformAndDragRows.h"

namespace tickfx {
namespace {

// Slots of the stage scratch; kState stands for the pool's own columns (the state at t).
enum Slot : int { kState = kPoolColumn, K1 = 0, K2, K3, K4, P2, V2, P3, V3, P4, V4 };

// The one pass's kernel under the forms' accelerations `a`: the four stages of a row in its
// registers, by the passes' own operations. The stage positions are not needed (a uniform force
// or a drag does not read the position), and the slopes and stage velocities never leave the row.
auto underForms(float h) {
  const float halfH = 0.5f * h;
  const float sixthH = h / 6.0f;
  return [=](const auto& a) {
    return [=](auto at, float* pos, float* vel, float* last) {
      const auto position = at.load(pos);
      const auto velocity = at.load(vel);
      const auto k1 = a.at(0, velocity);
      const auto v2 = velocity + k1 * halfH;
      const auto k2 = a.at(1, v2);
      const auto v3 = velocity + k2 * halfH;
      const auto k3 = a.at(1, v3);
      const auto v4 = velocity + k3 * h;
      const auto k4 = a.at(2, v4);
      const auto nextP = position + ((velocity + v2 * 2.0f) + (v3 * 2.0f + v4)) * sixthH;
      const auto nextV = velocity + ((k1 + k2 * 2.0f) + (k3 * 2.0f + k4)) * sixthH;
      at.copy(last, position);
      at.store(pos, nextP);
      at.store(vel, nextV);
      return CheckedPair{nextP, nextV};
    };
  };
}

// The tick's forms at the stages its one pass reads: t, t + dt/2 and t + dt. integrate() and
// boundTick() both ask here, so the bound runs on the forms the tick runs on.
std::optional<TickForms> rungeKutta4Forms(ParticlePool& pool, const ForceSet& forces,
                                          const StepTime& time) {
  return tickForms(pool, forces, time, {0, 1, 2});
}

}  // namespace

bool RungeKutta4::boundTick(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                            StateBound& bound) const {
  const auto forms = rungeKutta4Forms(pool, forces, time);
  if (!forms) return false;
  bound = boundTickUnderForms(*forms, underForms(time.dt()), bound);
  return true;
}

void RungeKutta4::integrate(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                            const StepRows& rows, NonfiniteCheck* check) {
  const float h = time.dt();
  const float halfH = 0.5f * h;
  const float sixthH = h / 6.0f;
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  const TickInstant t0 = time.stage(0), tHalf = time.stage(1), t1 = time.stage(2);

  if (const auto forms = rungeKutta4Forms(pool, forces, time)) {
    runStateUpdateUnderForms(pool, scratch_, rows, check, *forms, underForms(h));
    return;
  }
  auto velocityRows = [&](const Tile& tile, int slot) {
    return slot == kState ? rowsOf(v, tile.rows()) : tile.stage(slot);
  };
  // k_out = a(P_in, V_in, t)
  auto evaluate = [&](int pIn, int vIn, TickInstant t, int out) {
    return forcePass(pool, forces, pIn, vIn, t, out);
  };
  // (P_out, V_out) = (p + V_in · step, v + K_in · step)
  auto advance = [&](int vIn, int kIn, int pOut, int vOut, float step) {
    return [&, vIn, kIn, pOut, vOut, step](const Tile& tile) {
      Vec3Rows vi = velocityRows(tile, vIn), k = tile.stage(kIn), po = tile.stage(pOut),
               vo = tile.stage(vOut), pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows());
      for (int c = 0; c < 3; ++c) {
        po[c] = pr[c] + vi[c] * step;
        vo[c] = vr[c] + k[c] * step;
      }
    };
  };
  const TileCheck tiles = forcePassCheck(check, pool, forces, rows);
  runPasses(
      rows, forces.isLocal(), scratch_,
      {evaluate(kState, kState, t0, K1), advance(kState, K1, P2, V2, halfH),
       evaluate(P2, V2, tHalf, K2), advance(V2, K2, P3, V3, halfH), evaluate(P3, V3, tHalf, K3),
       advance(V3, K3, P4, V4, h), evaluate(P4, V4, t1, K4),
       [&](const Tile& tile) {
         Vec3Rows k1 = tile.stage(K1), k2 = tile.stage(K2), k3 = tile.stage(K3),
                  k4 = tile.stage(K4);
         Vec3Rows v2 = tile.stage(V2), v3 = tile.stage(V3), v4 = tile.stage(V4);
         Vec3Rows pr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
                  old = previousRowsOf(pool, rows, tile.rows());
         // s1..s4: the four slopes of the velocity (k1..k4); u2..u4: the stage velocities.
         const auto update = [sixthH](auto at, float* pos, float* vel, float* last, const float* s1,
                                      const float* s2, const float* s3, const float* s4,
                                      const float* u2, const float* u3, const float* u4) {
           const auto position = at.load(pos);
           const auto velocity = at.load(vel);
           const auto nextP =
               position +
               ((velocity + at.load(u2) * 2.0f) + (at.load(u3) * 2.0f + at.load(u4))) * sixthH;
           const auto nextV =
               velocity +
               ((at.load(s1) + at.load(s2) * 2.0f) + (at.load(s3) * 2.0f + at.load(s4))) * sixthH;
           at.copy(last, position);
           at.store(pos, nextP);
           at.store(vel, nextV);
           return CheckedPair{nextP, nextV};
         };
         const auto in = [](Eigen::Map<Eigen::ArrayXf>& column) {
           return static_cast<const float*>(column.data());
         };
         updateTile(tiles.sums, pool, tile.rows(), update, [&](int c) {
           return std::tuple(pr[c].data(), vr[c].data(), old[c].data(), in(k1[c]), in(k2[c]),
                             in(k3[c]), in(k4[c]), in(v2[c]), in(v3[c]), in(v4[c]));
         });
       }},
      tiles.afterEachTile);
}

}  // namespace tickfx
