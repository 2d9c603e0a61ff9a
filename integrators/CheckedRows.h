// The non-finite check folded into an integrator's last update loop over a tile (see
// NonfiniteCheck): the values a row has just written are still in registers, so testing them
// there costs about nothing, where a separate pass would read the tile again
// (docs/performance.md, the non-finite check).
#pragma once

#include <Eigen/Core>
#include <algorithm>
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
#include "particles/Isa.h"
#include "particles/NonfiniteState.h"
#include "particles/StartsSpan.h"

namespace tickfx {

/// Four rows of a column as one value: the register of SSE and NEON. Its arithmetic is lane by
/// lane and IEEE (no contraction: -ffp-contract=off), so rows computed four at a time have the
/// bits of the rows computed one by one.
using Lanes4 = float __attribute__((vector_size(16)));

/// Eight rows: the register of AVX, used only inside the AVX2 clones of the update loops
/// (updateBlocksAvx2), where every function taking or returning one is inlined. The same lane by
/// lane IEEE arithmetic: the bits of the rows computed one by one.
using Lanes8 = float __attribute__((vector_size(32)));

/// Sixteen rows: the register of AVX-512, used only inside the AVX-512 clones of the update loops
/// (updateBlocksAvx512), as Lanes8 in the AVX2 ones. Its comparisons compile to mask registers
/// (flushTiny()).
using Lanes16 = float __attribute__((vector_size(64)));

/// The integer lanes of a Lane, for its bits.
template <class Lane>
struct LaneBits;
template <>
struct LaneBits<Lanes4> {
  using type = std::int32_t __attribute__((vector_size(16)));
};
template <>
struct LaneBits<Lanes8> {
  using type = std::int32_t __attribute__((vector_size(32)));
};
template <>
struct LaneBits<Lanes16> {
  using type = std::int32_t __attribute__((vector_size(64)));
};

/// The number of rows a Lane holds (1 for float).
template <class Lane>
inline constexpr Eigen::Index kLanes = static_cast<Eigen::Index>(sizeof(Lane) / sizeof(float));

/// The smallest magnitude a stored value keeps, 2⁻⁶⁴ (as bits: exponent 63, mantissa 0). Below
/// it, flushTiny() stores a zero of the value's sign. Not FLT_MIN: a state value just above
/// FLT_MIN still makes subnormal intermediate products (v · dt, k · v · dt) for tens of ticks of a
/// decay, and on x86 those stall as much as subnormal state. With 2⁻⁶⁴, a stored value times up to
/// three factors of 2⁻²⁰ or more (a step of 1/60 s is 2⁻⁶ to 2⁻⁵, dt² 2⁻¹²) is still normal. In SI
/// units 2⁻⁶⁴ (5.4e-20 m, m/s) is no distance or speed an effect shows.
inline constexpr std::uint32_t kSmallestStoredBits = 0x1f800000U;
inline constexpr float kSmallestStored = 0x1p-64f;
static_assert(std::bit_cast<std::uint32_t>(kSmallestStored) == kSmallestStoredBits);

/// Lane by lane, `value` with every magnitude below kSmallestStored (subnormals included) replaced
/// by a zero of its sign; anything else (larger values, zeros, infinities, NaNs) unchanged. The
/// integrators store state through this, so that no state is subnormal or near it: a long decay
/// (a drag) reaches exact zeros instead of running for thousands of ticks on subnormals, which x86
/// and many ARM cores compute tens of times slower, and no tick computes a subnormal from the state
/// on the way. It is a rule on IEEE results in integer bits, the same on every platform, and leaves
/// the host's floating-point environment alone: hardware flush-to-zero (MXCSR FTZ, FPCR.FZ) is not
/// used because x86 detects tininess after rounding and AArch64 before, so the two flush different
/// results (docs/determinism.md, subnormals).
template <class Lane>
Lane flushTiny(Lane value) {
  if constexpr (std::is_same_v<Lane, float>) {
    const auto bits = std::bit_cast<std::uint32_t>(value);
    const bool tiny = (bits & 0x7fffffffU) < kSmallestStoredBits;
    return std::bit_cast<float>(tiny ? bits & 0x80000000U : bits);
  } else {
    using Bits = typename LaneBits<Lane>::type;
    const auto bits = std::bit_cast<Bits>(value);
    const Bits magnitude = bits & 0x7fffffff;
    if constexpr (std::is_same_v<Lane, Lanes16>) {
      // With AVX-512 the comparison is a mask register and the select one masked AND: three
      // instructions, where the form below takes four.
      const Bits tiny = magnitude < static_cast<std::int32_t>(kSmallestStoredBits);
      return std::bit_cast<Lane>(tiny ? bits & std::int32_t{-0x7fffffff - 1} : bits);
    } else {
      // all ones where kept: at least kSmallestStored, infinite or NaN
      const Bits keep = magnitude >= static_cast<std::int32_t>(kSmallestStoredBits);
      return std::bit_cast<Lane>(bits & (keep | std::int32_t{-0x7fffffff - 1}));
    }
  }
}

/// Where a row kernel reads and writes: row `i` of each column it is given (Lane = float), or
/// rows i..i+kLanes-1 (Lane = Lanes4, Lanes8 or Lanes16). A kernel is written once over `auto row`
/// and `auto` values, and runs a Lane of rows at a time in the loop's body and one at a time in its
/// tail. Without kCopies, copy() writes nothing: the loop's previous positions go to no reader.
template <class Lane, bool kCopies = true>
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
    if constexpr (!kCopies) {
      static_cast<void>(column);
      static_cast<void>(value);
    } else if constexpr (std::is_same_v<Lane, float>) {
      column[i] = value;
    } else {
      std::memcpy(column + i, &value, sizeof value);
    }
  }
  /// Writes `value` flushed (flushTiny()): every value an integrator computes is stored zero or
  /// at least kSmallestStored in magnitude.
  void store(float* column, Lane value) const {
    const Lane flushed = flushTiny(value);
    if constexpr (std::is_same_v<Lane, float>) {
      column[i] = flushed;
    } else {
      std::memcpy(column + i, &flushed, sizeof flushed);
    }
  }
};

/// `value` in every lane: a value a kernel computes that is the same for every row (its bits
/// unchanged, a negative zero included).
template <class Lane>
Lane broadcast(float value) {
  if constexpr (std::is_same_v<Lane, float>) {
    return value;
  } else {
    Lane out;
    for (Eigen::Index k = 0; k < kLanes<Lane>; ++k) out[k] = value;
    return out;
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

/// Runs `kernel(row, columns...)` over rows [0, n): kLanes<Lane> rows at a time (RowsAt<Lane>),
/// then the tail one by one (RowsAt<float>), reading and writing through `columns` (each a
/// distinct column: they are __restrict here, which lets the compiler keep values in registers
/// across a row's stores). With kCheck, sums what each call returns (see checkedValue) lane by
/// lane: a sum with a NaN or an infinity among its terms is not finite, whatever its order, so a
/// finite sum clears every row; a sum of finite terms can also overflow, and then the caller's
/// exact scan finds nothing and only time is lost. Returns whether some returned value may be
/// non-finite (always false without kCheck).
///
/// The sums are two Lanes that must stay in registers, one for each half of a two-Lane group, so
/// each is one add an iteration from its last value; sums the compiler keeps on the stack cost
/// loads and stores every iteration.
template <class Lane, bool kCheck, bool kCopies, class Kernel, class... Column>
[[gnu::always_inline]] inline bool updateRowsAs(Eigen::Index n, const Kernel& kernel,
                                                Column* __restrict... columns) {
  constexpr Eigen::Index w = kLanes<Lane>;
  Lane low = {}, high = {};
  Eigen::Index i = 0;
  for (; i + 2 * w <= n; i += 2 * w) {
    const Lane first = checkedValue(kernel(RowsAt<Lane, kCopies>{i}, columns...));
    const Lane second = checkedValue(kernel(RowsAt<Lane, kCopies>{i + w}, columns...));
    if constexpr (kCheck) {
      low += first;
      high += second;
    }
  }
  float tail = 0.0f;
  for (; i < n; ++i) {
    const float value = checkedValue(kernel(RowsAt<float, kCopies>{i}, columns...));
    if constexpr (kCheck) tail += value;
  }
  if constexpr (!kCheck) {
    return false;
  } else {
    const Lane sum = low + high;
    for (Eigen::Index k = 0; k < w; ++k) tail += sum[k];
    return !std::isfinite(tail);
  }
}

/// One path's row loop, handed to an UpdateComponent: `loop(n, kernel, columns...)` is
/// updateRowsAs<Lane, kCheck, kCopies>.
template <class Lane, bool kCheck, bool kCopies>
struct RowLoop {
  template <class Kernel, class... Column>
  [[gnu::always_inline]] bool operator()(Eigen::Index n, const Kernel& kernel,
                                         Column* __restrict... columns) const {
    return updateRowsAs<Lane, kCheck, kCopies>(n, kernel, columns...);
  }
};

/// `loop` (a RowLoop) with `kernel` over rows [offset, offset + count) of `columns`, a tuple of
/// pointers to their row 0: what an UpdateComponent does once it has its kernel and columns.
template <class Loop, class Kernel, class Columns>
bool loopAt(const Loop& loop, const Kernel& kernel, Eigen::Index offset, Eigen::Index count,
            const Columns& columns) {
  return std::apply([&](auto*... column) { return loop(count, kernel, (column + offset)...); },
                    columns);
}

/// Rows one component's update loop takes before the next component's (updateComponents()). A
/// tile's components in turn, each over the whole tile, would read two or three columns at a
/// time and restart the processor's prefetch streams at every turn; in blocks of this many rows
/// all the tile's columns stream at once, and a tick of 10⁶ rows runs about twice as fast
/// (docs/performance.md). Sixteen lanes take 512: each entry into a component's loop loads its
/// pointers and broadcasts its constants again, which 128 rows (eight registers) left unamortised,
/// and in cache a tick ran 1.4 times faster with 512; on four and eight lanes 512 gained nothing.
/// A multiple of the loop's group of rows (2 · kLanes<Lane>).
template <class Lane>
inline constexpr Eigen::Index kComponentBlockRows = std::is_same_v<Lane, Lanes16> ? 512 : 128;

/// No StartsSpan: every start is written (where kCopies).
struct NoSpanRows {};

/// A tile's rows under a StepRows::span: the span's axis's starts (as the loop has just written
/// them) and ends from the tile's row 0, and the mask whose groups of rows it clears.
struct SpanRows {
  StartsSpan span;
  const float* starts = nullptr;
  const float* ends = nullptr;
  std::uint64_t* written = nullptr;
  std::size_t firstRow = 0;  // the tile's row 0 less StepRows::writtenFrom: whole groups

  /// Whether a path of the tile's rows [offset, offset + count) may reach the span; where none
  /// does, clears their groups' bits (the loop then writes no other axis's starts for them).
  [[gnu::always_inline]] bool reached(Eigen::Index offset, Eigen::Index count) const {
    const float* __restrict a = starts + offset;
    const float* __restrict b = ends + offset;
    int any = 0;
    for (Eigen::Index i = 0; i < count; ++i) any |= span.reaches(a[i], b[i]);
    if (any != 0) return true;
    constexpr std::size_t g = StartsSpan::kGroupRows;
    const std::size_t from = firstRow + static_cast<std::size_t>(offset);
    for (std::size_t k = from / g; k < (from + static_cast<std::size_t>(count) + g - 1) / g; ++k)
      *written &= ~(std::uint64_t{1} << k);
    return false;
  }
};

/// `updateComponent(c, offset, count, loop)` for the three components c, block by block
/// (kComponentBlockRows<Lane>) over n rows; whether some call returned true. A row's components are
/// independent, so the order changes no bit. Under a span (SpanRows, unchecked with copies), a
/// block's span axis goes first, and the other two write no starts where the span rules out
/// every row of the block.
template <class Lane, bool kCheck, bool kCopies, class UpdateComponent, class Span>
[[gnu::always_inline]] inline bool updateBlocksAs(Eigen::Index n,
                                                  const UpdateComponent& updateComponent,
                                                  const Span& span) {
  bool suspect = false;
  constexpr Eigen::Index kRows = kComponentBlockRows<Lane>;
  for (Eigen::Index offset = 0; offset < n; offset += kRows) {
    const Eigen::Index count = std::min(kRows, n - offset);
    if constexpr (std::is_same_v<Span, SpanRows> && kCopies && !kCheck) {
      const int axis = span.span.axis;
      suspect |= updateComponent(axis, offset, count, RowLoop<Lane, false, true>{});
      const bool reached = span.reached(offset, count);
      for (int c = 0; c < 3; ++c) {
        if (c == axis) continue;
        suspect |= reached ? updateComponent(c, offset, count, RowLoop<Lane, false, true>{})
                           : updateComponent(c, offset, count, RowLoop<Lane, false, false>{});
      }
    } else {
      for (int c = 0; c < 3; ++c) {
        suspect |= updateComponent(c, offset, count, RowLoop<Lane, kCheck, kCopies>{});
      }
    }
  }
  return suspect;
}

/// updateBlocksAs() four rows a register (SSE2, NEON). Not inlined, so that the checked and
/// unchecked loops are compiled and placed alike and a measured difference between them is the
/// check's (docs/performance.md).
template <bool kCheck, bool kCopies, class UpdateComponent, class Span>
[[gnu::noinline]] bool updateBlocksBaseline(Eigen::Index n, const UpdateComponent& updateComponent,
                                            const Span& span) {
  return updateBlocksAs<Lanes4, kCheck, kCopies>(n, updateComponent, span);
}

#ifdef TICKFX_AVX2_CLONES
/// updateBlocksAs() compiled for AVX2, eight rows a register: the kernels and everything they
/// call are inlined here (flatten). The same operations on the same values as the baseline
/// loops, so the same bits (test_passes runs every scheme on both paths).
template <bool kCheck, bool kCopies, class UpdateComponent, class Span>
[[gnu::noinline, gnu::target("avx2"), gnu::flatten]] bool updateBlocksAvx2(
    Eigen::Index n, const UpdateComponent& updateComponent, const Span& span) {
  return updateBlocksAs<Lanes8, kCheck, kCopies>(n, updateComponent, span);
}

/// updateBlocksAs() compiled for AVX-512 (F), sixteen rows a register, flattened as the AVX2
/// clone is: the same operations on the same values, so the same bits (test_passes and
/// test_subnormals run every path).
template <bool kCheck, bool kCopies, class UpdateComponent, class Span>
[[gnu::noinline, gnu::target("avx2,avx512f"), gnu::flatten]] bool updateBlocksAvx512(
    Eigen::Index n, const UpdateComponent& updateComponent, const Span& span) {
  return updateBlocksAs<Lanes16, kCheck, kCopies>(n, updateComponent, span);
}
#endif

/// updateBlocksAs() on the path activeIsa() names, checked (summing what the kernels return)
/// when `check` is set.
template <bool kCheck, bool kCopies, class UpdateComponent, class Span = NoSpanRows>
bool updateBlocks(Eigen::Index n, const UpdateComponent& updateComponent, const Span& span = {}) {
#ifdef TICKFX_AVX2_CLONES
  switch (activeIsa()) {
    case Isa::Avx512:
      return updateBlocksAvx512<kCheck, kCopies>(n, updateComponent, span);
    case Isa::Avx2:
      return updateBlocksAvx2<kCheck, kCopies>(n, updateComponent, span);
    case Isa::Baseline:
      break;
  }
#endif
  return updateBlocksBaseline<kCheck, kCopies>(n, updateComponent, span);
}

/// `updateComponent(c, offset, count, loop)` (`loop`, a RowLoop, over rows [offset, offset +
/// count) of the tile `rows`, component c, returning whether some value may be non-finite) for
/// the three components, in blocks of rows on the path activeIsa() names, then, when one may
/// be, the exact scan that flags the rows. Checked (the loops sum what the kernels return) when
/// `check` is set. Without `copies` (unchecked only), the kernels' copies of the previous
/// position are not written: the caller's previous rows are a sink (previousRowsOf()). With
/// `span` (unchecked, with copies), the starts its span rules out are written on its axis alone.
template <class UpdateComponent, class Span = NoSpanRows>
void updateComponents(NonfiniteCheck* check, ParticlePool& pool, RowRange rows,
                      const UpdateComponent& updateComponent, bool copies = true,
                      const Span* span = nullptr) {
  const Eigen::Index n = rows.count();
  bool suspect = false;
  if (check != nullptr) {
    suspect = updateBlocks<true, true>(n, updateComponent);
  } else if (!copies) {
    suspect = updateBlocks<false, false>(n, updateComponent);
  } else if (span != nullptr) {
    suspect = updateBlocks<false, true>(n, updateComponent, *span);
  } else {
    suspect = updateBlocks<false, true>(n, updateComponent);
  }
  if (suspect) check->scan(pool, rows.begin, rows.end);
}

/// An integrator's checked update of one tile: `kernel` over the three components of `rows`
/// (`columnsOf(c)` gives component c's columns from the tile's first row, in the kernel's order,
/// as a tuple of pointers), then, when some value may be non-finite, the exact scan that flags
/// the tile's rows.
template <class Kernel, class ColumnsOf>
void updateTile(NonfiniteCheck* check, ParticlePool& pool, RowRange rows, const Kernel& kernel,
                const ColumnsOf& columnsOf) {
  updateComponents(check, pool, rows,
                   [&](int c, Eigen::Index offset, Eigen::Index count, const auto& loop) {
                     return loopAt(loop, kernel, offset, count, columnsOf(c));
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
