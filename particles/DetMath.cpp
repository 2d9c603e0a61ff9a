#include "particles/DetMath.h"

#include <boost/multiprecision/cpp_int.hpp>
#include <cmath>
#include <cstdint>
#include <string>

#include "particles/DetMathKernels.h"

namespace tickfx::det {
namespace {

using kernel::cosKernel;
using kernel::kCodyWaiteLimit;
using kernel::kTwoOverPi;
using kernel::sinKernel;

struct Reduced {
  double r;
  std::int64_t quadrant;
};

// ⌊2/π · 2^1216⌋ in hexadecimal. For any double x = m · 2^e (m < 2^53, e <= 971) the product with
// it keeps at least 245 bits below the binary point, and the bits of 2/π it leaves out move
// x · 2/π by less than 2^-192: far below the 2^-61 that the closest double comes to a multiple
// of π/2, so the quadrant and the leading bits of the remainder are exact.
constexpr const char* kTwoOverPiHex =
    "a2f9836e4e441529fc2757d1f534ddc0db6295993c439041fe5163abdebbc561"
    "b7246e3a424dd2e006492eea09d1921cfe1deb1cb129a73ee88235f52ebb4484"
    "e99c7026b45f7e413991d639835339f49c845f8bbdf9283b1ff897ffde05980f"
    "ef2f118b5a0a6d1f6d367ecf27cb09b74f463f669e5fea2d7527bac7ebe5f17b"
    "3d0739f78a5292ea6bfb5fb11f8d5d0856033046fc7b6bab";

Reduced reduceLarge(double x) {
  using Big = boost::multiprecision::cpp_int;
  static const Big twoOverPi(std::string("0x") + kTwoOverPiHex);
  constexpr int kBits = 1216;
  int e = 0;
  const double m = std::frexp(std::fabs(x), &e);
  const auto mantissa = static_cast<std::uint64_t>(std::ldexp(m, 53));
  const int shift = kBits - (e - 53);  // |x| · 2/π = product / 2^shift
  const Big product = Big(mantissa) * twoOverPi;
  const Big whole = product >> shift;
  std::int64_t quadrant = static_cast<std::int64_t>(static_cast<unsigned>(whole & 3));
  // The fraction's leading 128 bits, as f / 2^128 in [0, 1); past one half, the next quadrant.
  const Big fraction = (product - (whole << shift)) >> (shift - 128);
  const Big half = Big(1) << 127;
  double f = 0.0;
  if (fraction >= half) {
    quadrant += 1;
    f = -std::ldexp(((Big(1) << 128) - fraction).convert_to<double>(), -128);
  } else {
    f = std::ldexp(fraction.convert_to<double>(), -128);
  }
  const double r = f * (0.5 * kPi);
  return x < 0.0 ? Reduced{-r, -quadrant} : Reduced{r, quadrant};
}

Reduced reduce(double x) {
  if (std::fabs(x) >= kCodyWaiteLimit) return reduceLarge(x);
  // nearbyint under the default rounding mode is exact and the same everywhere.
  const double k = std::nearbyint(x * kTwoOverPi);
  return {kernel::codyWaite(x, k), static_cast<std::int64_t>(k)};
}

// sin(q·π/2 + r) for |r| ≤ π/4: a quadrant's turn swaps the kernels and their signs. cos(x) is
// sin(x + π/2), the next quadrant, so every function below takes its values from here.
double sinInQuadrant(std::int64_t q, double r) {
  switch (q & 3) {
    case 0:
      return sinKernel(r);
    case 1:
      return cosKernel(r);
    case 2:
      return -sinKernel(r);
    default:
      return -cosKernel(r);
  }
}

}  // namespace

double sin(double x) {
  if (!std::isfinite(x)) return std::nan("");
  const Reduced red = reduce(x);
  return sinInQuadrant(red.quadrant, red.r);
}

double cos(double x) {
  if (!std::isfinite(x)) return std::nan("");
  const Reduced red = reduce(x);
  return sinInQuadrant(red.quadrant + 1, red.r);
}

void sincos(double x, double& sine, double& cosine) {
  if (!std::isfinite(x)) {
    sine = cosine = std::nan("");
    return;
  }
  const Reduced red = reduce(x);
  sine = sinInQuadrant(red.quadrant, red.r);
  cosine = sinInQuadrant(red.quadrant + 1, red.r);
}

double cbrt(double x) {
  if (!(x > 0.0)) return x == 0.0 ? 0.0 : std::nan("");
  if (!std::isfinite(x)) return x;
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m · 2^e, m in [0.5, 1): exact
  // Start at 2^(e/3), rounded toward the root; frexp and ldexp are exact, so the start is too.
  double y = std::ldexp(1.0, e >= 0 ? e / 3 : -((-e) / 3));
  y = y * (m > 0.75 ? 1.0 : 0.8);
  // Newton's step either reaches a fixed point or, for about one input in 15, ends up swapping
  // two neighbouring doubles until the 60 steps are spent. Such a cycle is detected (step i + 1
  // gives step i − 1's value) and the 60th value taken from its parity: the bits of running all
  // 60 steps, at a tenth of the cost.
  double before = y;
  for (int i = 0; i < kernel::kCbrtSteps; ++i) {
    const double next = kernel::cbrtStep(y, x);
    if (next == y) break;
    if (i > 0 && next == before) return kernel::cbrtCycleEnd(i, before, y);
    before = y;
    y = next;
  }
  return y;
}

}  // namespace tickfx::det
