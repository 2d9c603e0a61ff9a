// The non-finite check folded into an integrator's last update loop over a tile (see
// NonfiniteCheck): the values a row has just written are still in registers, so testing them
// there costs about nothing, where a separate pass would read the tile again
// (docs/performance.md, the non-finite check).
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <tuple>
#include <type_traits>

#include "fields/ForceModule.h"
#include "fields/ForceSet.h"
#include "integrators/NonfiniteExceptions.h"
#include "integrators/StagePasses.h"
#include "particles/NonfiniteState.h"

namespace tickfx {

/// Four rows of a column as one value: the register of SSE and NEON. Its arithmetic is lane by
/// lane and IEEE (no contraction: -ffp-contract=off), so rows computed four at a time have the
/// bits of the rows computed one by one.
using Lanes4 = float __attribute__((vector_size(16)));

/// Lane by lane, `value` with every subnormal replaced by a zero of its sign; normal values,
/// zeros, infinities and NaNs unchanged. The integrators store state through this, so that no
/// state stays subnormal: a long decay (a drag) reaches exact zeros instead of running for
/// thousands of ticks on subnormals, which x86 and many ARM cores compute tens of times slower.
/// It is a rule on IEEE results in integer bits, the same on every platform, and leaves the
/// host's floating-point environment alone: hardware flush-to-zero (MXCSR FTZ, FPCR.FZ) is not
/// used because x86 detects tininess after rounding and AArch64 before, so the two flush
/// different results (docs/determinism.md, subnormals).
template <class Lane>
Lane flushTiny(Lane value) {
  if constexpr (std::is_same_v<Lane, float>) {
    const auto bits = std::bit_cast<std::uint32_t>(value);
    const bool tiny = (bits & 0x7fffffffU) < 0x00800000U;
    return std::bit_cast<float>(tiny ? bits & 0x80000000U : bits);
  } else {
    using Bits = std::int32_t __attribute__((vector_size(16)));
    const auto bits = std::bit_cast<Bits>(value);
    const Bits keep = (bits & 0x7fffffff) >= 0x00800000;  // all ones where normal, inf or NaN
    return std::bit_cast<Lane>(bits & (keep | std::int32_t{-0x7fffffff - 1}));
  }
}

/// Where a row kernel reads and writes: row `i` of each column it is given (Lane = float), or
/// rows i..i+3 (Lane = Lanes4). A kernel is written once over `auto row` and `auto` values, and
/// runs four rows at a time in the loop's body and one at a time in its tail.
template <class Lane>
struct RowsAt {
  Eigen::Index i;

  Lane load(const float* column) const {
    if constexpr (std::is_same_v<Lane, float>) {
      return column[i];
    } else {
      Lane value;
      std::memcpy(&value, column + i, sizeof value);
      return value;
    }
  }
  /// Writes `value` unchanged: a copy of a value already stored (the previous position).
  void copy(float* column, Lane value) const {
    if constexpr (std::is_same_v<Lane, float>) {
      column[i] = value;
    } else {
      std::memcpy(column + i, &value, sizeof value);
    }
  }
  /// Writes `value` flushed (flushTiny()): every value an integrator computes is stored normal or
  /// zero.
  void store(float* column, Lane value) const {
    const Lane flushed = flushTiny(value);
    if constexpr (std::is_same_v<Lane, float>) {
      column[i] = flushed;
    } else {
      std::memcpy(column + i, &flushed, sizeof flushed);
    }
  }
};

/// `value` in every lane: a value a kernel computes that is the same for every row.
template <class Lane>
Lane broadcast(float value) {
  if constexpr (std::is_same_v<Lane, float>) {
    return value;
  } else {
    return Lane{value, value, value, value};
  }
}

/// What a row kernel hands to the check: the one value its new state is not finite without
/// (a Lane), or, when its new position does not contain its new velocity, both (a CheckedPair).
template <class Lane>
struct CheckedPair {
  Lane position;
  Lane velocity;
};
template <class Lane>
CheckedPair(Lane, Lane) -> CheckedPair<Lane>;

/// The value the check sums for what a kernel returned: a pair is added to itself first, so that
/// the sums' loop-carried chain has one add a row group, not two.
template <class Lane>
Lane checkedValue(Lane value) {
  return value;
}
template <class Lane>
Lane checkedValue(const CheckedPair<Lane>& pair) {
  return pair.position + pair.velocity;
}

/// Runs `kernel(row, columns...)` over rows [0, n): four rows at a time (RowsAt<Lanes4>), then
/// the tail one by one (RowsAt<float>), reading and writing through `columns` (each a distinct
/// column: they are __restrict here, which lets the compiler keep values in registers across a
/// row's stores). With kCheck, sums what each call returns (see checkedValue) lane by lane: a sum
/// with a NaN or an infinity among its terms is not finite, whatever its order, so a finite sum
/// clears every row; a sum of finite terms can also overflow, and then the caller's exact scan
/// finds nothing and only time is lost. Returns whether some returned value may be non-finite
/// (always false without kCheck).
///
/// The sums are two Lanes4 that must stay in registers, one for each half of an 8-row group, so
/// each is one add an iteration from its last value; sums the compiler keeps on the stack cost
/// loads and stores every iteration.
///
/// Not inlined, so that the checked and unchecked loops are compiled and placed alike and a
/// measured difference between them is the check's (docs/performance.md).
template <bool kCheck, class Kernel, class... Column>
[[gnu::noinline]] bool updateRowsChecked(Eigen::Index n, const Kernel& kernel,
                                         Column* __restrict... columns) {
  Lanes4 low = {}, high = {};
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8) {
    const Lanes4 first = checkedValue(kernel(RowsAt<Lanes4>{i}, columns...));
    const Lanes4 second = checkedValue(kernel(RowsAt<Lanes4>{i + 4}, columns...));
    if constexpr (kCheck) {
      low += first;
      high += second;
    }
  }
  float tail = 0.0f;
  for (; i < n; ++i) {
    const float value = checkedValue(kernel(RowsAt<float>{i}, columns...));
    if constexpr (kCheck) tail += value;
  }
  if constexpr (!kCheck) {
    return false;
  } else {
    const Lanes4 sum = low + high;
    return !std::isfinite(((sum[0] + sum[1]) + (sum[2] + sum[3])) + tail);
  }
}

/// updateRowsChecked() with the check on when `check` is set (the step checks this tick).
template <class Kernel, class... Column>
bool updateRows(const NonfiniteCheck* check, Eigen::Index n, const Kernel& kernel,
                Column*... columns) {
  return check != nullptr ? updateRowsChecked<true>(n, kernel, columns...)
                          : updateRowsChecked<false>(n, kernel, columns...);
}

/// `updateComponent(c)` (updateRows() over component c of `rows`, returning whether some value
/// may be non-finite) for the three components, then, when one may be, the exact scan that flags
/// the rows.
template <class UpdateComponent>
void updateComponents(NonfiniteCheck* check, ParticlePool& pool, RowRange rows,
                      const UpdateComponent& updateComponent) {
  bool suspect = false;
  for (int c = 0; c < 3; ++c) suspect |= updateComponent(c);
  if (suspect) check->scan(pool, rows.begin, rows.end);
}

/// An integrator's checked update of one tile: updateRows() over the three components of `rows`
/// (`columnsOf(c)` gives component c's columns, in the kernel's order, as a tuple of pointers),
/// then, when some value may be non-finite, the exact scan that flags the tile's rows.
template <class Kernel, class ColumnsOf>
void updateTile(NonfiniteCheck* check, ParticlePool& pool, RowRange rows, const Kernel& kernel,
                const ColumnsOf& columnsOf) {
  const Eigen::Index n = rows.count();
  updateComponents(check, pool, rows, [&](int c) {
    return std::apply([&](auto*... columns) { return updateRows(check, n, kernel, columns...); },
                      columnsOf(c));
  });
}

/// The check of a tile by exceptions (see NonfiniteCheck::steppedRowsFinite()), once its passes
/// are done: the whole tile is scanned when they raised a kNonfiniteExceptions flag, else its rows
/// spawned this tick (from `fresh` on), whose values the tick did not make from checked ones.
inline void checkByExceptions(NonfiniteCheck& check, ParticlePool& pool, RowRange r,
                              std::size_t fresh) {
  const RowRange scanned = takeNonfiniteExceptions() ? r : intersect(r, fresh, r.end);
  if (scanned.count() == 0) return;
  check.scan(pool, scanned.begin, scanned.end);
  takeNonfiniteExceptions();  // the scan's own sums of what it found: not the next tile's
}

/// How a tick's passes check their tiles: `sums` for their update loops' updateTile() (nullptr:
/// unchecked) and `afterEachTile` for runPasses().
struct TileCheck {
  NonfiniteCheck* sums = nullptr;
  RowPass afterEachTile;
};

/// The TileCheck of a tick's passes: by exceptions (the update loops unchecked, checkByExceptions()
/// after each tile) when the stepped rows start finite and `arithmeticOnly`: every other input of
/// the tile's arithmetic is a finite constant, and the tile's passes run on one thread (so the
/// flags of its thread are the tile's). Else by sums (or none, without `check`).
inline TileCheck tileCheck(NonfiniteCheck* check, ParticlePool& pool, const StepRows& rows,
                           bool arithmeticOnly) {
  if (check == nullptr || !check->steppedRowsFinite() || !arithmeticOnly) return {check, {}};
  return {nullptr, [check, &pool, fresh = rows.fresh](const Tile& tile) {
            checkByExceptions(*check, pool, tile.rows(), fresh);
          }};
}

/// The TileCheck of a tick's force passes: by exceptions when every force is local (fused tiles)
/// and arithmetic only (ForceSet::arithmeticOnly).
inline TileCheck forcePassCheck(NonfiniteCheck* check, ParticlePool& pool, const ForceSet& forces,
                                const StepRows& rows) {
  return tileCheck(check, pool, rows, forces.isLocal() && forces.arithmeticOnly());
}

}  // namespace tickfx
