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

void sincosBlock(const double* x, double* sine, double* cosine, std::size_t n) {
  kernel::sincosSmall(x, sine, cosine, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(std::fabs(x[i]) < kernel::kCodyWaiteLimit)) det::sincos(x[i], sine[i], cosine[i]);
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

void cbrtBlock(const double* x, double* root, std::size_t n) { kernel::cbrtBlock(x, root, n); }

}  // namespace tickfx::det
