// How an integrator's passes are scheduled over the rows, and where its stage values live.
#pragma once

#include <array>
#include <functional>
#include <initializer_list>
#include <vector>

#include "fields/ForceSet.h"
#include "integrators/StepRows.h"

namespace tickfx {

/// Stage values an integrator keeps during one tick (accelerations, RK4 midpoints, ...): `count`
/// vector quantities per row. In a split run they are pool-sized columns owned here (kept between
/// ticks so the steady state allocates nothing); in a fused run each tile uses a small buffer on
/// its thread's stack and these columns are not touched.
class StageScratch {
 public:
  static constexpr int kMaxColumns = 10;
  explicit StageScratch(int count);
  int count() const { return count_; }
  Vec3Column& column(int k) {
    TICKFX_ASSERT(k >= 0 && k < count_, "a stage column this integrator did not ask for");
    return columns_[static_cast<std::size_t>(k)];
  }
  /// Grows the pool-sized columns to `rows` (split runs only).
  void ensureRows(std::size_t rows);

 private:
  int count_;
  std::vector<Vec3Column> columns_;
};

/// What one pass sees: a range of rows and the stage values for exactly those rows.
class Tile {
 public:
  static constexpr std::size_t kRows = 512;

  /// `stage[k][c]` points at the value of row `base` for stage value k, component c.
  Tile(RowRange rows, float* const (*stage)[3], int count, std::size_t base)
      : rows_(rows), stage_(stage), count_(count), base_(base) {}

  RowRange rows() const { return rows_; }
  /// Stage value `k` for this tile's rows, writable.
  Vec3Rows stage(int k) const {
    TICKFX_ASSERT(k >= 0 && k < count_, "a stage value out of range");
    TICKFX_ASSERT(rows_.begin >= base_, "a tile whose rows start below its stage values");
    const std::size_t i = rows_.begin - base_;
    return {stage_[k][0] + i, stage_[k][1] + i, stage_[k][2] + i, rows_.count()};
  }
  /// Stage value `k` as forces read it (ForceInput::position or velocity).
  Vec3View view(int k) const {
    TICKFX_ASSERT(k >= 0 && k < count_, "a stage value out of range");
    return {stage_[k][0], stage_[k][1], stage_[k][2], base_};
  }
  int count() const { return count_; }

 private:
  RowRange rows_;
  float* const (*stage_)[3];
  int count_;
  std::size_t base_;
};

/// One pass of an integrator over a tile: a force evaluation or a state update.
using RowPass = std::function<void(const Tile&)>;

/// Runs `passes` over `rows`. With `fused` (every force local) each tile of Tile::kRows rows runs
/// all passes in turn while its rows and stage values are in L1/L2 cache; otherwise each pass
/// finishes for all rows before the next starts, because a non-local force reads rows that other
/// blocks are updating. Each row sees exactly the same arithmetic either way, so the bits do not
/// depend on the mode, the tile size, the thread count or how the rows are split into calls.
///
/// `afterEachTile`, when set, runs on each tile once every pass is done with it (in a fused run
/// while the tile's rows are still in cache): a read-only check of the tile's new state.
void runPasses(const StepRows& rows, bool fused, StageScratch& scratch,
               std::initializer_list<RowPass> passes, const RowPass& afterEachTile = {});

/// In forcePass() and flowPass(): the pool's own column instead of a stage value.
inline constexpr int kPoolColumn = -1;

/// The pass that writes the forces' total acceleration (ForceSet::evaluate) at the positions
/// `position` and velocities `velocity` (stage slots, or kPoolColumn) and instant `at` into
/// stage value `out`.
RowPass forcePass(const ParticlePool& pool, const ForceSet& forces, int position, int velocity,
                  TickInstant at, int out);

/// The same for the velocity that advection modules prescribe (ForceSet::evaluateVelocity).
RowPass flowPass(const ParticlePool& pool, const ForceSet& forces, int position, TickInstant at,
                 int out);

/// Rows of `r` that are also in [begin, end).
RowRange intersect(RowRange r, std::size_t begin, std::size_t end);

/// Whether a step of `rows` writes its rows' starting positions to the pool's previousPosition():
/// when the step keeps them (a frame interpolates across it) or the scheme reads them as state.
inline bool writesPreviousColumn(const ParticlePool& pool, const StepRows& rows) {
  return rows.keepPrevious || pool.previousIsState();
}

/// Whether a step of `rows` writes its rows' starting positions where they are read: the pool's
/// column (writesPreviousColumn()) or the caller's StepRows::starts.
inline bool writesPreviousRows(const ParticlePool& pool, const StepRows& rows) {
  return writesPreviousColumn(pool, rows) || rows.starts[0] != nullptr;
}

/// Where a step of `rows` writes its rows' starting positions: row r's component c at
/// to[c][r − base]. The pool's previousPosition() (base 0) when writesPreviousColumn(), else the
/// caller's StepRows::starts (base rows.rows.begin) where set, else nowhere (to[0] null).
struct StartsTarget {
  std::array<float*, 3> to{};
  std::size_t base = 0;
};
StartsTarget startsTargetOf(ParticlePool& pool, const StepRows& rows);

/// Where a step of `rows` writes the starting positions of tile rows `r`: its startsTargetOf()
/// rows, or where that is nowhere, a sink on the calling thread that nothing reads (the same
/// stores, into L1: the column is not touched).
Vec3Rows previousRowsOf(ParticlePool& pool, const StepRows& rows, RowRange r);

/// Rows `r` of a pool column, writable or read-only.
inline Vec3Rows rowsOf(Vec3Column& c, RowRange r) { return Vec3Rows::of(c, r); }
inline auto rowsOf(FloatColumn& c, RowRange r) { return c.segment(r.offset(), r.count()); }

}  // namespace tickfx
