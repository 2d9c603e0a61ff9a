#include "integrators/StagePasses.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "particles/ParallelFor.h"

namespace tickfx {

namespace {

// Checked before the columns are made: a negative count would first ask for 2^64 of them.
int checkedColumnCount(int count) {
  if (count < 0 || count > StageScratch::kMaxColumns) {
    throw std::invalid_argument("a scheme takes 0 to " + std::to_string(StageScratch::kMaxColumns) +
                                " stage columns");
  }
  return count;
}

}  // namespace

StageScratch::StageScratch(int count)
    : count_(checkedColumnCount(count)), columns_(static_cast<std::size_t>(count_)) {}

void StageScratch::ensureRows(std::size_t rows) {
  for (Vec3Column& c : columns_) {
    if (static_cast<std::size_t>(c.x.size()) < rows) c.resize(static_cast<Eigen::Index>(rows));
  }
}

void runPasses(const StepRows& rows, bool fused, StageScratch& scratch,
               std::initializer_list<RowPass> passes, const RowPass& afterEachTile) {
  const int count = scratch.count();
  const std::size_t first = rows.rows.begin;
  // Calls body(begin, end) for absolute rows, in parallel blocks or on this thread.
  const auto overRows = [&](const std::function<void(std::size_t, std::size_t)>& body) {
    if (rows.serial) {
      body(first, rows.rows.end);
    } else {
      parallelForRows(rows.rows.end - first,
                      [&](std::size_t b, std::size_t e) { body(first + b, first + e); });
    }
  };
  if (fused) {
    overRows([&](std::size_t b, std::size_t e) {
      alignas(64) float buffer[StageScratch::kMaxColumns * 3 * Tile::kRows];
      float* stage[StageScratch::kMaxColumns][3];
      for (std::size_t t = b; t < e; t += Tile::kRows) {
        for (int k = 0; k < count; ++k) {
          for (int c = 0; c < 3; ++c) stage[k][c] = buffer + (k * 3 + c) * Tile::kRows;
        }
        const Tile tile(RowRange{t, std::min(e, t + Tile::kRows)}, stage, count, t);
        for (const RowPass& pass : passes) pass(tile);
        if (afterEachTile) afterEachTile(tile);
      }
    });
    return;
  }
  // Split passes index their stage columns by pool row.
  TICKFX_ASSERT(!rows.serial, "split passes over a block of rows");
  scratch.ensureRows(rows.rows.end);
  float* stage[StageScratch::kMaxColumns][3];
  for (int k = 0; k < count; ++k) {
    for (int c = 0; c < 3; ++c) stage[k][c] = scratch.column(k)[c].data();
  }
  const auto overAllRows = [&](const RowPass& pass) {
    overRows([&](std::size_t b, std::size_t e) { pass(Tile(RowRange{b, e}, stage, count, 0)); });
  };
  for (const RowPass& pass : passes) overAllRows(pass);
  if (afterEachTile) overAllRows(afterEachTile);
}

namespace {

Vec3View viewOf(const Tile& tile, const Vec3Column& column, int slot) {
  return slot == kPoolColumn ? Vec3View::of(column) : tile.view(slot);
}

}  // namespace

RowPass forcePass(const ParticlePool& pool, const ForceSet& forces, int position, int velocity,
                  TickInstant at, int out) {
  return [&pool, &forces, position, velocity, at, out](const Tile& tile) {
    Vec3Rows a = tile.stage(out);
    const ForceInput in{pool, viewOf(tile, pool.position(), position),
                        viewOf(tile, pool.velocity(), velocity), at};
    forces.evaluate(in, tile.rows(), a);
  };
}

RowPass flowPass(const ParticlePool& pool, const ForceSet& forces, int position, TickInstant at,
                 int out) {
  return [&pool, &forces, position, at, out](const Tile& tile) {
    Vec3Rows u = tile.stage(out);
    const ForceInput in{pool, viewOf(tile, pool.position(), position),
                        Vec3View::of(pool.velocity()), at};
    forces.evaluateVelocity(in, tile.rows(), u);
  };
}

StartsTarget startsTargetOf(ParticlePool& pool, const StepRows& rows) {
  if (writesPreviousColumn(pool, rows)) {
    Vec3Column& column = pool.previousPosition();
    TICKFX_ASSERT(rows.rows.end <= static_cast<std::size_t>(column.x.size()),
                  "a row range past the end of its column");
    return {{column.x.data(), column.y.data(), column.z.data()}, 0};
  }
  return {rows.starts, rows.rows.begin};
}

Vec3Rows previousRowsOf(ParticlePool& pool, const StepRows& rows, RowRange r) {
  if (const StartsTarget t = startsTargetOf(pool, rows); t.to[0] != nullptr) {
    TICKFX_ASSERT(rows.rows.begin <= r.begin && r.end <= rows.rows.end,
                  "a tile outside the step's rows");
    const std::size_t at = r.begin - t.base;
    return {t.to[0] + at, t.to[1] + at, t.to[2] + at, r.count()};
  }
  // One sink for all three components: written, never read. A tile's rows at most (a fused
  // tile, or a parallel block of split passes).
  thread_local std::vector<float> sink;
  const std::size_t n = r.end - r.begin;
  if (sink.size() < n) sink.resize(std::max<std::size_t>(n, Tile::kRows));
  return {sink.data(), sink.data(), sink.data(), r.count()};
}

RowRange intersect(RowRange r, std::size_t begin, std::size_t end) {
  const std::size_t b = std::max(r.begin, begin);
  const std::size_t e = std::min(r.end, end);
  return b < e ? RowRange{b, e} : RowRange{b, b};
}

}  // namespace tickfx
