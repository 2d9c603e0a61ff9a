// The arithmetic det::sincos and det::cbrt are made of, shared by the scalar functions
// (DetMath.cpp) and their block forms (DetMathBlock.cpp) so that both evaluate the very same
// expressions: with -ffp-contract=off an expression gives the same bits wherever it is compiled.
// Internal: not installed.
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "particles/DetMath.h"

namespace tickfx::det::kernel {

// π/2 split into three parts whose products with a small integer are exact (Cody–Waite), so the
// reduced argument keeps full precision while k · kPio2Hi is exact (below kCodyWaiteLimit).
inline constexpr double kPio2Hi = 1.57079632673412561417e+00;
inline constexpr double kPio2Mid = 6.07710050630396597660e-11;
inline constexpr double kPio2Lo = 2.02226624879595063154e-21;
inline constexpr double kTwoOverPi = 6.36619772367581382433e-01;

// Cody–Waite is exact while k · kPio2Hi is (kPio2Hi has 33 bits: k < 2^20); past 2^19 the
// reduction multiplies by 2/π in exact integers instead (Payne–Hanek).
inline constexpr double kCodyWaiteLimit = 524288.0;  // 2^19

// Taylor polynomials on [−π/4, π/4]; the first omitted term is below 2.1e-14 relative for sine
// and 1.1e-15 for cosine, well under the float resolution the simulation keeps.
inline double sinKernel(double r) {
  const double z = r * r;
  double p = -1.0 / 1307674368000.0;  // −1/15!
  p = p * z + 1.0 / 6227020800.0;     // 1/13!
  p = p * z - 1.0 / 39916800.0;       // −1/11!
  p = p * z + 1.0 / 362880.0;         // 1/9!
  p = p * z - 1.0 / 5040.0;           // −1/7!
  p = p * z + 1.0 / 120.0;            // 1/5!
  p = p * z - 1.0 / 6.0;              // −1/3!
  return r + r * z * p;
}

inline double cosKernel(double r) {
  const double z = r * r;
  double p = 1.0 / 20922789888000.0;  // 1/16!
  p = p * z - 1.0 / 87178291200.0;    // −1/14!
  p = p * z + 1.0 / 479001600.0;      // 1/12!
  p = p * z - 1.0 / 3628800.0;        // −1/10!
  p = p * z + 1.0 / 40320.0;          // 1/8!
  p = p * z - 1.0 / 720.0;            // −1/6!
  p = p * z + 1.0 / 24.0;             // 1/4!
  p = p * z - 0.5;                    // −1/2!
  return 1.0 + z * p;
}

// x − k·π/2 in three exact steps, for the integer-valued k nearest x · 2/π (|x| < 2^19).
inline double codyWaite(double x, double k) {
  return ((x - k * kPio2Hi) - k * kPio2Mid) - k * kPio2Lo;
}

// Cube roots go 60 Newton steps at most, stopping at a fixed point or on a two-value cycle.
inline constexpr int kCbrtSteps = 60;

// One Newton step towards the cube root of x from y.
inline double cbrtStep(double y, double x) { return y - (y * y * y - x) / (3.0 * y * y); }

// The value the 60 steps end on when, at step `i`, the step gave step i − 1's value back: the
// iteration then swaps `before` and `y` until the steps are spent, so the parity picks.
inline double cbrtCycleEnd(int i, double before, double y) {
  return (kCbrtSteps - (i - 1)) % 2 == 0 ? before : y;
}

inline std::uint64_t bitsOf(double x) { return std::bit_cast<std::uint64_t>(x); }
inline double fromBits(std::uint64_t b) { return std::bit_cast<double>(b); }

// Adding and subtracting 1.5 · 2^52 rounds |y| < 2^51 to the nearest integer, ties to even: what
// std::nearbyint does under the default rounding mode, without the library call that keeps a loop
// from vectorising. The sum's low mantissa bits are that integer modulo 2^51 (two's complement
// for negative ones), so its bits also give the quadrant.
inline constexpr double kRoundShift = 0x1.8p52;

// det::sincos for |x| < 2^19: the Cody–Waite reduction and both kernels, then the quadrant's
// choice and signs made with selects rather than det::sincos's switch. The same values: a turn by
// a quadrant swaps the kernels, and negation flips the sign bit alone. Inline, so that a caller
// compiled for wider vectors (SpawnBatch's AVX2 path) vectorises it with them.
inline void sincosSmall(const double* x, double* sine, double* cosine, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const double y = x[i] * kTwoOverPi;
    const double shifted = y + kRoundShift;
    // std::nearbyint keeps the sign of a zero (−0.3 gives −0.0), which the reduction can see.
    const double k = std::copysign(shifted - kRoundShift, y);
    const double r = codyWaite(x[i], k);
    const std::uint64_t q = bitsOf(shifted);
    const std::uint64_t s = bitsOf(sinKernel(r)), c = bitsOf(cosKernel(r));
    // sin in quadrant q is ±sin(r) or ±cos(r); cos is sin in quadrant q + 1. Selected with masks
    // of the integer bits, which every vector unit has for 64-bit lanes.
    const std::uint64_t odd = 0 - (q & 1);
    sine[i] = fromBits(((c & odd) | (s & ~odd)) ^ ((q & 2) << 62));
    cosine[i] = fromBits(((s & odd) | (c & ~odd)) ^ (((q + 1) & 2) << 62));
  }
}

// The cube roots of one lane group, at most kCbrtLanes of them, every x positive and normal: the
// Newton steps of det::cbrt taken by all lanes together, each lane's root kept from the step
// where det::cbrt stops (a fixed point, or a two-value cycle). The groups are small so that a
// lane needing many steps holds few others back.
inline constexpr std::size_t kCbrtLanes = 32;

inline void cbrtLanes(const double* x, double* root, std::size_t n) {
  // Per lane: the iterate, the one before, and the root once known (0 until then: the root of a
  // positive x never is). Selects of doubles, not branches or integer masks of double compares,
  // are what g++ 12 vectorises here.
  double y[kCbrtLanes], before[kCbrtLanes], found[kCbrtLanes];
  for (std::size_t j = 0; j < n; ++j) {
    // x = m · 2^e with m in [0.5, 1), as std::frexp gives them for a normal x; the start
    // 2^(e/3) (e/3 rounded toward zero) is std::ldexp(1.0, e/3), exact.
    const std::uint64_t b = bitsOf(x[j]);
    const int e = static_cast<int>(b >> 52) - 1022;
    const double m = fromBits((b & 0x000fffffffffffffULL) | 0x3fe0000000000000ULL);
    const double start = fromBits(static_cast<std::uint64_t>(e / 3 + 1023) << 52);
    y[j] = start * (m > 0.75 ? 1.0 : 0.8);
    before[j] = y[j];
    found[j] = 0.0;
  }
  for (int i = 0; i < kCbrtSteps; ++i) {
    // Top bit set while some lane has no root: its bits minus one wrap around.
    std::uint64_t pending = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double yj = y[j], bj = before[j];
      const double next = cbrtStep(yj, x[j]);
      // A fixed point ends on y; a cycle (the step gives the value before back) as det::cbrt's
      // parity says. At step 0 `before` is y, so the fixed point is taken, as det::cbrt does.
      const double now = next == yj ? yj : (next == bj ? cbrtCycleEnd(i, bj, yj) : 0.0);
      const double kept = found[j] == 0.0 ? now : found[j];
      found[j] = kept;
      pending |= bitsOf(kept) - 1;
      before[j] = yj;
      y[j] = next;
    }
    if ((pending >> 63) == 0) break;
  }
  // Lanes still moving after 60 steps end on the 60th value, as det::cbrt does.
  for (std::size_t j = 0; j < n; ++j) root[j] = found[j] == 0.0 ? y[j] : found[j];
}

inline bool positiveNormal(double x) { return x >= 0x1p-1022 && x <= 0x1.fffffffffffffp1023; }

// det::cbrtBlock(), inline for the same reason as sincosSmall.
inline void cbrtBlock(const double* x, double* root, std::size_t n) {
  double lanes[kCbrtLanes], roots[kCbrtLanes];
  std::size_t index[kCbrtLanes];
  std::size_t filled = 0;
  const auto flush = [&] {
    cbrtLanes(lanes, roots, filled);
    for (std::size_t j = 0; j < filled; ++j) root[index[j]] = roots[j];
    filled = 0;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!positiveNormal(x[i])) {
      root[i] = det::cbrt(x[i]);  // zero, subnormal, negative, infinite or nan
      continue;
    }
    lanes[filled] = x[i];
    index[filled] = i;
    if (++filled == kCbrtLanes) flush();
  }
  if (filled > 0) flush();
}

}  // namespace tickfx::det::kernel
