#include "integrators/Advection.h"

#include "integrators/Integrator.h"

namespace tickfx {

std::string_view advectionSchemeName(AdvectionScheme scheme) {
  switch (scheme) {
    case AdvectionScheme::Euler:
      return "euler";
    case AdvectionScheme::Midpoint:
      return "midpoint";
    case AdvectionScheme::Heun:
      return "heun";
    case AdvectionScheme::RungeKutta4:
      return "rk4";
  }
  return "";
}

int advectionOrder(AdvectionScheme scheme) {
  switch (scheme) {
    case AdvectionScheme::Euler:
      return 1;
    case AdvectionScheme::Midpoint:
    case AdvectionScheme::Heun:
      return 2;
    case AdvectionScheme::RungeKutta4:
      return 4;
  }
  return 0;
}

namespace {

enum Slot : int { kState = kPoolColumn, K1 = 0, K2, K3, K4, X2, X3, X4 };

}  // namespace

void Advection::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                     const StepRows& rows, const RowPass& afterEachTile) {
  const float h = time.dt();
  const float halfH = 0.5f * h;
  // PointAdvect's constants, in its order of operations: (h·S)·(1/6) with S the stage sum.
  const float sixth = static_cast<float>(1.0 / 6.0);
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  const TickInstant t0 = time.stage(0), tHalf = time.stage(1), t1 = time.stage(2);

  // k_out = u(X_in, t)
  auto sample = [&](int xIn, TickInstant t, int out) {
    return flowPass(pool, forces, xIn, t, out);
  };
  // X_out = x + step·K_in
  auto predict = [&](int kIn, float step, int out) {
    return [&, kIn, step, out](const Tile& tile) {
      Vec3Rows k = tile.stage(kIn), xo = tile.stage(out), xr = rowsOf(p, tile.rows());
      for (int c = 0; c < 3; ++c) xo[c] = xr[c] + k[c] * step;
    };
  };
  // The step itself: v = mean velocity, x += displacement.
  auto finish = [&](const Tile& tile) {
    Vec3Rows k1 = tile.stage(K1), xr = rowsOf(p, tile.rows()), vr = rowsOf(v, tile.rows()),
             old = previousRowsOf(pool, rows, tile.rows());
    for (int c = 0; c < 3; ++c) {
      old[c] = xr[c];
      switch (scheme_) {
        case AdvectionScheme::Euler:
          vr[c] = k1[c];
          xr[c] += h * k1[c];
          break;
        case AdvectionScheme::Midpoint: {
          Vec3Rows k2 = tile.stage(K2);
          vr[c] = k2[c];
          xr[c] += h * k2[c];
          break;
        }
        case AdvectionScheme::Heun: {
          Vec3Rows k2 = tile.stage(K2);
          vr[c] = (k1[c] + k2[c]) * 0.5f;
          xr[c] += h * vr[c];
          break;
        }
        case AdvectionScheme::RungeKutta4: {
          Vec3Rows k2 = tile.stage(K2), k3 = tile.stage(K3), k4 = tile.stage(K4);
          const auto s = (k1[c] + (k2[c] + k3[c]) * 2.0f) + k4[c];
          vr[c] = s * sixth;
          xr[c] += (h * s) * sixth;
          break;
        }
      }
    }
  };
  const bool fused = forces.isLocal();
  switch (scheme_) {
    case AdvectionScheme::Euler:
      runPasses(rows, fused, scratch_, {sample(kState, t0, K1), finish}, afterEachTile);
      break;
    case AdvectionScheme::Midpoint:
      runPasses(rows, fused, scratch_,
                {sample(kState, t0, K1), predict(K1, halfH, X2), sample(X2, tHalf, K2), finish},
                afterEachTile);
      break;
    case AdvectionScheme::Heun:
      runPasses(rows, fused, scratch_,
                {sample(kState, t0, K1), predict(K1, h, X2), sample(X2, t1, K2), finish},
                afterEachTile);
      break;
    case AdvectionScheme::RungeKutta4:
      runPasses(rows, fused, scratch_,
                {sample(kState, t0, K1), predict(K1, halfH, X2), sample(X2, tHalf, K2),
                 predict(K2, halfH, X3), sample(X3, tHalf, K3), predict(K3, h, X4),
                 sample(X4, t1, K4), finish},
                afterEachTile);
      break;
  }
}

}  // namespace tickfx
