// The arithmetic det::sincos and det::cbrt are made of, shared by the scalar functions
// (DetMath.cpp) and their block forms (DetMathBlock.cpp) so that both evaluate the very same
// expressions: with -ffp-contract=off an expression gives the same bits wherever it is compiled.
// Internal: not installed.
#pragma once

#include <cstdint>

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

}  // namespace tickfx::det::kernel
