#include "integrators/Advection.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>

#include "integrators/Integrator.h"
#include "integrators/LeafOrder.h"
#include "particles/ParallelFor.h"

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

// PointAdvect's constant, in its order of operations: (h·S)·(1/6) with S the stage sum.
const float kSixth = static_cast<float>(1.0 / 6.0);

// X_out = x + step·K_in (PointAdvect's order of operations), for one tile's values.
void predictValues(Vec3Rows x, Vec3Rows k, float step, Vec3Rows out) {
  for (int c = 0; c < 3; ++c) out[c] = x[c] + k[c] * step;
}

// The step itself for one tile's values: v = the mean velocity, x += the displacement.
// stage(K1..K4) gives the tile's stage velocities (those the scheme has).
template <class Stage>
void finishValues(AdvectionScheme scheme, float h, Vec3Rows x, Vec3Rows v, const Stage& stage) {
  Vec3Rows k1 = stage(K1);
  for (int c = 0; c < 3; ++c) {
    switch (scheme) {
      case AdvectionScheme::Euler:
        v[c] = k1[c];
        x[c] += h * k1[c];
        break;
      case AdvectionScheme::Midpoint: {
        Vec3Rows k2 = stage(K2);
        v[c] = k2[c];
        x[c] += h * k2[c];
        break;
      }
      case AdvectionScheme::Heun: {
        Vec3Rows k2 = stage(K2);
        v[c] = (k1[c] + k2[c]) * 0.5f;
        x[c] += h * v[c];
        break;
      }
      case AdvectionScheme::RungeKutta4: {
        Vec3Rows k2 = stage(K2), k3 = stage(K3), k4 = stage(K4);
        const auto sum = (k1[c] + (k2[c] + k3[c]) * 2.0f) + k4[c];
        v[c] = sum * kSixth;
        x[c] += (h * sum) * kSixth;
        break;
      }
    }
  }
}

// After K1 = u(x, t): stage i + 1 predicts X_{i+1} = x + step·K_i into slot X2 + i − 1 and
// samples K_{i+1} = u(X_{i+1}, at) into slot K1 + i.
struct LaterStage {
  float step;
  TickInstant at;
};

// The tile of rows in leaf order: the stage values, the gathered positions (then the new ones)
// and the new velocities, Tile::kRows values each. Allocated once per thread.
struct GatheredTile {
  enum : int { kX = X4 + 1, kV = X4 + 2, kSlots = X4 + 3 };
  alignas(64) float values[kSlots][3][Tile::kRows];
  std::size_t n = 0;
  Vec3Rows slot(int k) {
    return {values[k][0], values[k][1], values[k][2], static_cast<Eigen::Index>(n)};
  }
};

struct LeafScratch {
  LeafOrder order;
  GatheredTile tile;
};

// This thread's scratch: on the heap, so that thread-local storage holds a pointer alone.
LeafScratch& leafScratch() {
  thread_local std::unique_ptr<LeafScratch> scratch = std::make_unique<LeafScratch>();
  return *scratch;
}

Vec3View bufferView(Vec3Rows v) { return {v.x.data(), v.y.data(), v.z.data(), 0}; }

void gatherRows(const Vec3Column& column, const std::uint32_t* rows, Vec3Rows out) {
  for (int c = 0; c < 3; ++c) {
    const float* from = column[c].data();
    for (Eigen::Index j = 0; j < out.x.size(); ++j) out[c][j] = from[rows[j]];
  }
}

// Row rows[j]'s value to[c][rows[j] − base] for each component c.
void scatterRows(Vec3Rows values, const std::uint32_t* rows, const std::array<float*, 3>& to,
                 std::size_t base) {
  for (int c = 0; c < 3; ++c) {
    float* const out = to[static_cast<std::size_t>(c)];
    for (Eigen::Index j = 0; j < values.x.size(); ++j) out[rows[j] - base] = values[c][j];
  }
}

void scatterRows(Vec3Rows values, const std::uint32_t* rows, Vec3Column& column) {
  scatterRows(values, rows, {column.x.data(), column.y.data(), column.z.data()}, 0);
}

// Calls body(block) for consecutive blocks of LeafOrder::blockRows() of `rows`: one task each,
// or on this thread for a serial call.
void forEachBlock(const StepRows& rows, const std::function<void(RowRange)>& body) {
  const std::size_t first = rows.rows.begin, end = rows.rows.end;
  const std::size_t size = LeafOrder::blockRows(end - first);
  const auto block = [&](std::size_t b) {
    body(RowRange{first + b * size, std::min(end, first + (b + 1) * size)});
  };
  const std::size_t blocks = (end - first + size - 1) / size;
  if (rows.serial) {
    for (std::size_t b = 0; b < blocks; ++b) block(b);
  } else {
    parallelForTasks(blocks, block);
  }
}

}  // namespace

struct Advection::Step {
  ParticlePool& pool;
  const ForceSet& forces;
  AdvectionScheme scheme;
  float h;
  TickInstant t0, tHalf, t1;
  // Where each row's starting position goes (previousRowsOf()'s target).
  StartsTarget starts;

  // The stages after the first, in order; returns how many.
  int laterStages(LaterStage (&out)[3]) const {
    const float halfH = 0.5f * h;
    switch (scheme) {
      case AdvectionScheme::Euler:
        return 0;
      case AdvectionScheme::Midpoint:
        out[0] = {halfH, tHalf};
        return 1;
      case AdvectionScheme::Heun:
        out[0] = {h, t1};
        return 1;
      case AdvectionScheme::RungeKutta4:
        out[0] = {halfH, tHalf};
        out[1] = {halfH, tHalf};
        out[2] = {h, t1};
        return 3;
    }
    return 0;
  }

  // Every stage of `tile`, whose rows are `rows`: the positions gathered, the results scattered.
  void gathered(const std::uint32_t* rows, GatheredTile& tile) const {
    const auto slot = [&](int k) { return tile.slot(k); };
    const auto sample = [&](int x, TickInstant at, int out) {
      Vec3Rows u = slot(out);
      forces.evaluateVelocityGathered(pool, bufferView(slot(x)), rows, at, u);
    };
    gatherRows(pool.position(), rows, slot(GatheredTile::kX));
    sample(GatheredTile::kX, t0, K1);
    LaterStage later[3];
    const int count = laterStages(later);
    for (int i = 0; i < count; ++i) {
      predictValues(slot(GatheredTile::kX), slot(K1 + i), later[i].step, slot(X2 + i));
      sample(X2 + i, later[i].at, K2 + i);
    }
    if (starts.to[0] != nullptr) scatterRows(slot(GatheredTile::kX), rows, starts.to, starts.base);
    finishValues(scheme, h, slot(GatheredTile::kX), slot(GatheredTile::kV), slot);
    scatterRows(slot(GatheredTile::kX), rows, pool.position());
    scatterRows(slot(GatheredTile::kV), rows, pool.velocity());
  }
};

void Advection::step(ParticlePool& pool, const ForceSet& forces, const StepTime& time,
                     const StepRows& rows, const RowPass& afterEachTile) {
  const Step s{pool,          forces,        scheme_,       time.dt(),
               time.stage(0), time.stage(1), time.stage(2), startsTargetOf(pool, rows)};
  const bool fused = forces.isLocal();
  if (visits_ == Visits::LeafOrder && fused && forces.gathersVelocity()) {
    stepLeafOrder(s, rows, afterEachTile);
  } else {
    stepRowOrder(s, rows, fused, afterEachTile);
  }
}

void Advection::stepLeafOrder(const Step& s, const StepRows& rows, const RowPass& afterEachTile) {
  forEachBlock(rows, [&](RowRange block) {
    LeafScratch& scratch = leafScratch();
    if (!scratch.order.build(s.forces, s.pool.position(), block)) {
      stepRowOrder(s, rows.partOf(block), true, afterEachTile);
      return;
    }
    const std::size_t n = scratch.order.size();
    for (std::size_t t = 0; t < n; t += Tile::kRows) {
      scratch.tile.n = std::min(Tile::kRows, n - t);
      s.gathered(scratch.order.rows() + t, scratch.tile);
    }
    if (!afterEachTile) return;
    for (std::size_t t = block.begin; t < block.end; t += Tile::kRows) {
      afterEachTile(Tile(RowRange{t, std::min(block.end, t + Tile::kRows)}, nullptr, 0, t));
    }
  });
}

void Advection::stepRowOrder(const Step& s, const StepRows& rows, bool fused,
                             const RowPass& afterEachTile) {
  Vec3Column& p = s.pool.position();
  Vec3Column& v = s.pool.velocity();

  // k_out = u(X_in, t)
  auto sample = [&](int xIn, TickInstant t, int out) {
    return flowPass(s.pool, s.forces, xIn, t, out);
  };
  // X_out = x + step·K_in
  auto predict = [&](int kIn, float step, int out) {
    return [&, kIn, step, out](const Tile& tile) {
      predictValues(rowsOf(p, tile.rows()), tile.stage(kIn), step, tile.stage(out));
    };
  };
  // The step itself: v = mean velocity, x += displacement.
  auto finish = [&](const Tile& tile) {
    Vec3Rows xr = rowsOf(p, tile.rows()), old = previousRowsOf(s.pool, rows, tile.rows());
    for (int c = 0; c < 3; ++c) old[c] = xr[c];
    finishValues(s.scheme, s.h, xr, rowsOf(v, tile.rows()), [&](int k) { return tile.stage(k); });
  };
  const float h = s.h, halfH = 0.5f * h;
  const TickInstant t0 = s.t0, tHalf = s.tHalf, t1 = s.t1;
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
