// Transcendental functions that give the same bits with every compiler, flag and libm.
#pragma once

namespace tickfx::det {

/// π to double precision.
inline constexpr double kPi = 3.141592653589793238462643383279502884;

/// Sine of `x` radians. Built only from +, −, × and exact range reduction, so with
/// -ffp-contract=off it is bitwise reproducible across gcc and clang at any optimisation level,
/// unlike std::sin whose result depends on the libm and on constant folding. The reduction is
/// exact over the whole double range (Cody–Waite below 2^19, exact integer products with 1216
/// bits of 2/π beyond), so the result is within about 1e-14 of sin(x) for every finite x and
/// never outside [−1, 1]; nan for inf and nan.
double sin(double x);

/// Cosine of `x` radians; same guarantees as det::sin.
double cos(double x);

/// det::sin(x) and det::cos(x), the same bits, from one range reduction.
void sincos(double x, double& sine, double& cosine);

/// Cube root of `x` >= 0 by Newton's method from an exact power-of-two start; deterministic.
double cbrt(double x);

}  // namespace tickfx::det
