// The non-finite check folded into an integrator's last update loop over a tile (see
// NonfiniteCheck): the values a row has just written are still in registers, so testing them
// costs about nothing, where a separate pass re-reading the tile cost 11 % of a semi-implicit
// Euler tick at 10⁴ particles.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <tuple>
#include <type_traits>

#include "fields/ForceModule.h"
#include "particles/NonfiniteState.h"

namespace tickfx {

/// What a row's update hands to the check when its new position does not contain its new
/// velocity: both values (a kernel whose new position does returns that one float).
using CheckedPair = std::array<float, 2>;

/// Runs `kernel(i, columns...)` for i in [0, n): one row's update, reading and writing the rows
/// through `columns` (each a distinct column: they are __restrict here, which is what lets the
/// loop vectorise; the same kernel reaching its columns through captured pointers measured 3.5×
/// slower). With kCheck, adds what each call returns (a float, or both values of a CheckedPair,
/// one after the other) into kLanes partial sums, so the compiler vectorises the sum without
/// reassociating anything (which -ffast-math is banned for). A sum with a NaN or an infinity among
/// its terms is not finite, whatever its order, so a finite sum clears every row; a sum of finite
/// terms can also overflow, and then the caller's exact scan finds nothing and only time is lost.
/// A pair's values are added to the sum one by one rather than to each other first: the value
/// computed last (the velocity, at the end of a long dependency chain in a one-pass scheme) is
/// then one add from the end, not two, and a loop bound by that chain's latency measured the
/// difference. Returns whether some returned value may be non-finite (always false without kCheck).
///
/// Not inlined: inlined into an integrator's tile lambda, the checked and unchecked loops were
/// placed so differently that the checked tick measured 4 to 9 % slower for reasons that had
/// nothing to do with the check (tick_bench, 10⁴ particles); as functions of their own they
/// measure the same.
template <bool kCheck, class Kernel, class... Column>
[[gnu::noinline]] bool updateRowsChecked(Eigen::Index n, const Kernel& kernel,
                                         Column* __restrict... columns) {
  using Value = decltype(kernel(Eigen::Index{0}, columns...));
  constexpr bool kPair = std::is_same_v<Value, CheckedPair>;
  constexpr int kLanes = 8;
  float sums[kLanes] = {};
  Eigen::Index i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int lane = 0; lane < kLanes; ++lane) {
      const Value value = kernel(i + lane, columns...);
      if constexpr (kCheck && kPair) {
        sums[lane] += value[0];
        sums[lane] += value[1];
      } else if constexpr (kCheck) {
        sums[lane] += value;
      }
    }
  }
  for (; i < n; ++i) {
    const Value value = kernel(i, columns...);
    if constexpr (kCheck && kPair) {
      sums[0] += value[0];
      sums[0] += value[1];
    } else if constexpr (kCheck) {
      sums[0] += value;
    }
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
