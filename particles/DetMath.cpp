#include "particles/DetMath.h"

#include <cmath>
#include <cstdint>

namespace tickfx::det {
namespace {

// π/2 split into three parts whose products with a small integer are exact (Cody–Waite), so the
// reduced argument keeps full precision for |x| up to about 1e5.
constexpr double kPio2Hi = 1.57079632673412561417e+00;
constexpr double kPio2Mid = 6.07710050630396597660e-11;
constexpr double kPio2Lo = 2.02226624879595063154e-21;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;

// Taylor polynomials on [−π/4, π/4]; the first omitted term is below 2.1e-14 relative for sine
// and 1.1e-15 for cosine, well under the float resolution the simulation keeps.
double sinKernel(double r) {
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

double cosKernel(double r) {
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

struct Reduced {
  double r;
  std::int64_t quadrant;
};

Reduced reduce(double x) {
  // nearbyint under the default rounding mode is exact and the same everywhere.
  const double k = std::nearbyint(x * kTwoOverPi);
  const double r = ((x - k * kPio2Hi) - k * kPio2Mid) - k * kPio2Lo;
  return {r, static_cast<std::int64_t>(k)};
}

}  // namespace

double sin(double x) {
  if (!std::isfinite(x)) return std::nan("");
  const Reduced red = reduce(x);
  switch (red.quadrant & 3) {
    case 0:
      return sinKernel(red.r);
    case 1:
      return cosKernel(red.r);
    case 2:
      return -sinKernel(red.r);
    default:
      return -cosKernel(red.r);
  }
}

double cos(double x) {
  if (!std::isfinite(x)) return std::nan("");
  const Reduced red = reduce(x);
  switch (red.quadrant & 3) {
    case 0:
      return cosKernel(red.r);
    case 1:
      return -sinKernel(red.r);
    case 2:
      return -cosKernel(red.r);
    default:
      return sinKernel(red.r);
  }
}

double cbrt(double x) {
  if (!(x > 0.0)) return x == 0.0 ? 0.0 : std::nan("");
  if (!std::isfinite(x)) return x;
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m · 2^e, m in [0.5, 1): exact
  // Start at 2^(e/3), rounded toward the root; frexp and ldexp are exact, so the start is too.
  double y = std::ldexp(1.0, e >= 0 ? e / 3 : -((-e) / 3));
  y = y * (m > 0.75 ? 1.0 : 0.8);
  for (int i = 0; i < 60; ++i) {
    const double next = y - (y * y * y - x) / (3.0 * y * y);
    if (next == y) break;
    y = next;
  }
  return y;
}

}  // namespace tickfx::det
