// Which rows one integrator step advances.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "particles/ParticlePool.h"
#include "particles/RowViews.h"
#include "particles/StartsSpan.h"

namespace tickfx {

/// The rows one integrator step advances: every row of the pool, in parallel (a tick), or one
/// block of rows on the calling thread (a fused frame, whose caller runs its blocks in parallel
/// and takes each through all the frame's ticks).
struct StepRows {
  RowRange rows;
  /// Rows [fresh, rows.end) were spawned this tick: schemes with history start them on their own.
  std::size_t fresh = 0;
  /// Run on the calling thread: the caller parallelises.
  bool serial = false;
  /// Write each row's starting position to pool.previousPosition() (a frame interpolates across
  /// this tick). Else the schemes that do not read it as state write it nowhere: a tick then
  /// neither reads nor writes the column (ParticlePool::previousIsState()).
  bool keepPrevious = true;
  /// Without keepPrevious, where the step writes its rows' starting positions instead of nowhere:
  /// three arrays (x, y, z), row r's value at index r − rows.begin (a block's collision pass reads
  /// them right after its step: ColliderSet::collideRows()). Null: nowhere. A scheme that reads
  /// the previous position as state writes the pool's column all the same.
  std::array<float*, 3> starts{};
  /// With starts: the span outside which a row's path meets no collider. A step may then write
  /// only the span's axis of the starts of a group of StartsSpan::kGroupRows rows (from
  /// writtenFrom on) of which no path reaches the span, and clears the group's bit in *written;
  /// a group whose bit stays set has every start written. Without a span, every bit stays set.
  StartsSpan span{};
  std::uint64_t* written = nullptr;
  std::size_t writtenFrom = 0;

  /// The rows of `part`, a part of these rows, on the calling thread, their starts moved with them.
  StepRows partOf(RowRange part) const {
    StepRows p{part, fresh, true, keepPrevious, starts, span, written, writtenFrom};
    if (starts[0] != nullptr) {
      for (float*& s : p.starts) s += part.begin - rows.begin;
    }
    return p;
  }
  /// Every row of `pool`, its unstepped rows fresh, in parallel.
  static StepRows wholePool(const ParticlePool& pool, bool keepPrevious = true) {
    return {RowRange{0, pool.size()}, pool.firstUnstepped(), false, keepPrevious};
  }
};

}  // namespace tickfx
