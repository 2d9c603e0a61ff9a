// The non-finite check folded into an integrator's last update loop over a tile (see
// NonfiniteCheck): the values a row has just written are still in registers, so testing them
// costs about nothing, where a separate pass re-reading the tile cost 11 % of a semi-implicit
// Euler tick at 10⁴ particles.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <tuple>

#include "fields/ForceModule.h"
#include "particles/NonfiniteState.h"

namespace tickfx {

/// Runs `kernel(i, columns...)` for i in [0, n): one row's update, reading and writing the rows
/// through `columns` (each a distinct column: they are __restrict here, which is what lets the
/// loop vectorise; the same kernel reaching its columns through captured pointers measured 3.5×
/// slower). With kCheck, adds what each call returns (the row's new position component plus its
/// new velocity component, say) into kLanes partial sums, so the compiler vectorises the sum
/// without reassociating anything (which -ffast-math is banned for). A sum with a NaN or an
/// infinity among its terms is not finite, whatever its order, so a finite sum clears every row;
/// a sum of finite terms can also overflow, and then the caller's exact scan finds nothing and only
/// time is lost. Returns whether some returned value may be non-finite (always false without
/// kCheck).
///
/// Not inlined: inlined into an integrator's tile lambda, the checked and unchecked loops were
/// placed so differently that the checked tick measured 4 to 9 % slower for reasons that had
/// nothing to do with the check (tick_bench, 10⁴ particles); as functions of their own they
/// measure the same.
template <bool kCheck, class Kernel, class... Column>
[[gnu::noinline]] bool updateRowsChecked(Eigen::Index n, const Kernel& kernel,
                                         Column* __restrict... columns) {
  constexpr int kLanes = 8;
  float sums[kLanes] = {};
  Eigen::Index i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int lane = 0; lane < kLanes; ++lane) {
      const float value = kernel(i + lane, columns...);
      if constexpr (kCheck) sums[lane] += value;
    }
  }
  for (; i < n; ++i) {
    const float value = kernel(i, columns...);
    if constexpr (kCheck) sums[0] += value;
  }
  if constexpr (!kCheck) {
    return false;
  } else {
    float total = 0.0f;
    for (const float sum : sums) total += sum;
    return !std::isfinite(total);
  }
}

/// updateRowsChecked() with the check on when `check` is set (the step checks this tick).
template <class Kernel, class... Column>
bool updateRows(const NonfiniteCheck* check, Eigen::Index n, const Kernel& kernel,
                Column*... columns) {
  return check != nullptr ? updateRowsChecked<true>(n, kernel, columns...)
                          : updateRowsChecked<false>(n, kernel, columns...);
}

/// An integrator's checked update of one tile: updateRows() over the three components of `rows`
/// (`columnsOf(c)` gives component c's columns, in the kernel's order, as a tuple of pointers),
/// then, when some value may be non-finite, the exact scan that flags the tile's rows.
template <class Kernel, class ColumnsOf>
void updateTile(NonfiniteCheck* check, ParticlePool& pool, RowRange rows, const Kernel& kernel,
                const ColumnsOf& columnsOf) {
  const Eigen::Index n = rows.count();
  bool suspect = false;
  for (int c = 0; c < 3; ++c) {
    suspect |= std::apply(
        [&](auto*... columns) { return updateRows(check, n, kernel, columns...); }, columnsOf(c));
  }
  if (suspect) check->scan(pool, rows.begin, rows.end);
}

}  // namespace tickfx
