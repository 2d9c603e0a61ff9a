// How an integrator's passes are scheduled over the rows.
#pragma once

#include <functional>
#include <initializer_list>

#include "fields/ForceModule.h"

namespace tickfx {

/// One pass of an integrator over a row range: a force evaluation or a state update.
using RowPass = std::function<void(RowRange)>;

/// Runs `passes` over rows [0, rows). With `fused` (all forces local) every block runs all
/// passes in turn while its rows are in cache; otherwise each pass finishes for all rows before
/// the next starts, because a non-local force reads rows that other blocks are updating.
/// Either way each row sees exactly the same arithmetic, so the bits do not depend on the mode.
void runPasses(std::size_t rows, bool fused, std::initializer_list<RowPass> passes);

/// Rows of `r` that are also in [begin, end).
RowRange intersect(RowRange r, std::size_t begin, std::size_t end);

/// A column segment for rows `r`.
inline auto rowsOf(FloatColumn& c, RowRange r) { return c.segment(r.offset(), r.count()); }
inline auto rowsOf(const FloatColumn& c, RowRange r) { return c.segment(r.offset(), r.count()); }

/// Grows scratch columns to the pool's storage (never shrinks, so steady state allocates nothing).
void ensureRows(Vec3Column& c, std::size_t rows);

}  // namespace tickfx
