#include "particles/DetMathBlock.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

#include "particles/DetMath.h"
#include "particles/DetMathKernels.h"

namespace tickfx::det {
namespace {

using kernel::kCodyWaiteLimit;

// Adding and subtracting 1.5 · 2^52 rounds |y| < 2^51 to the nearest integer, ties to even: what
// std::nearbyint does under the default rounding mode, without the library call that keeps a loop
// from vectorising. The sum's low mantissa bits are that integer modulo 2^51 (two's complement
// for negative ones), so its bits also give the quadrant.
constexpr double kRoundShift = 0x1.8p52;

std::uint64_t bitsOf(double x) { return std::bit_cast<std::uint64_t>(x); }
double fromBits(std::uint64_t b) { return std::bit_cast<double>(b); }

// det::sincos for |x| < 2^19: the Cody–Waite reduction and both kernels, then the quadrant's
// choice and signs made with selects rather than det::sincos's switch. The same values: a turn by
// a quadrant swaps the kernels, and negation flips the sign bit alone.
void sincosSmall(const double* x, double* sine, double* cosine, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const double y = x[i] * kernel::kTwoOverPi;
    const double shifted = y + kRoundShift;
    // std::nearbyint keeps the sign of a zero (−0.3 gives −0.0), which the reduction can see.
    const double k = std::copysign(shifted - kRoundShift, y);
    const double r = kernel::codyWaite(x[i], k);
    const std::uint64_t q = bitsOf(shifted);
    const std::uint64_t s = bitsOf(kernel::sinKernel(r)), c = bitsOf(kernel::cosKernel(r));
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
constexpr std::size_t kCbrtLanes = 32;

void cbrtLanes(const double* x, double* root, std::size_t n) {
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
  for (int i = 0; i < kernel::kCbrtSteps; ++i) {
    // Top bit set while some lane has no root: its bits minus one wrap around.
    std::uint64_t pending = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double yj = y[j], bj = before[j];
      const double next = kernel::cbrtStep(yj, x[j]);
      // A fixed point ends on y; a cycle (the step gives the value before back) as det::cbrt's
      // parity says. At step 0 `before` is y, so the fixed point is taken, as det::cbrt does.
      const double now = next == yj ? yj : (next == bj ? kernel::cbrtCycleEnd(i, bj, yj) : 0.0);
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

bool positiveNormal(double x) { return x >= 0x1p-1022 && x <= 0x1.fffffffffffffp1023; }

}  // namespace

void sincosBlock(const double* x, double* sine, double* cosine, std::size_t n) {
  sincosSmall(x, sine, cosine, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(std::fabs(x[i]) < kCodyWaiteLimit)) det::sincos(x[i], sine[i], cosine[i]);
  }
}

// std::sqrt's errno path (a library call for a negative argument) keeps g++ and clang from
// vectorising a loop of it unless -fno-math-errno, which the build does not set: the vector
// instructions are used directly. max(x, 0) of either unit gives 0 for nan and −0, as
// std::max(0.0, x) does, and both square roots are IEEE's, correctly rounded.
void sqrtClampedBlock(double* x, std::size_t n) {
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128d zero = _mm_setzero_pd();
  for (; i + 2 <= n; i += 2)
    _mm_storeu_pd(x + i, _mm_sqrt_pd(_mm_max_pd(_mm_loadu_pd(x + i), zero)));
#elif defined(__aarch64__)
  const float64x2_t zero = vdupq_n_f64(0.0);
  for (; i + 2 <= n; i += 2) {
    // vmaxnmq would keep a nan; a compare and a select give std::max's 0 for it.
    const float64x2_t v = vld1q_f64(x + i);
    vst1q_f64(x + i, vsqrtq_f64(vbslq_f64(vcgtq_f64(v, zero), v, zero)));
  }
#endif
  for (; i < n; ++i) x[i] = std::sqrt(std::max(0.0, x[i]));
}

void cbrtBlock(const double* x, double* root, std::size_t n) {
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

}  // namespace tickfx::det
