// Arithmetic on finite values makes a value that is not finite only through an operation that
// raises a floating-point exception: invalid (inf − inf, 0 · inf, 0/0 give NaN), overflow or
// division by zero (±inf). The flags of these exceptions are sticky and per thread, and the
// hardware sets them for free (MXCSR on x86, FPSR on AArch64). So a loop whose inputs are all
// finite can be checked by testing the flags once it is done, with no operation per value; an
// input that is already NaN or infinite spreads without raising anything, so the inputs have to
// be known finite some other way (NonfiniteCheck::steppedRowsFinite()).
#pragma once

#include <cfenv>

#if defined(__x86_64__) && defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace tickfx {

/// FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO. Inexact and underflow are left alone: they are the
/// ordinary life of finite arithmetic.
inline constexpr int kNonfiniteExceptions = FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO;

/// Whether some kNonfiniteExceptions flag is raised on this thread; clears them if so. Raised
/// flags may be older than the loop being checked (code before it on the thread): the caller's
/// answer to them (an exact scan) must be harmless when nothing is wrong.
///
/// On x86-64 it reads and clears MXCSR's flags alone: every float and double operation there is an
/// SSE or AVX one (nothing in tickfx uses long double), and fetestexcept() and feclearexcept()
/// also read or rewrite the x87 unit's status (fnstsw, fnstenv/fldenv), which cost more than the
/// check of a tile in cache.
inline bool takeNonfiniteExceptions() {
#if defined(__x86_64__) && defined(__SSE__)
  constexpr unsigned kFlags = _MM_EXCEPT_INVALID | _MM_EXCEPT_OVERFLOW | _MM_EXCEPT_DIV_ZERO;
  static_assert(FE_INVALID == _MM_EXCEPT_INVALID && FE_OVERFLOW == _MM_EXCEPT_OVERFLOW &&
                FE_DIVBYZERO == _MM_EXCEPT_DIV_ZERO);
  const unsigned csr = _mm_getcsr();
  if ((csr & kFlags) == 0) return false;
  _mm_setcsr(csr & ~kFlags);  // the control bits (rounding, masks) as they were
  return true;
#else
  if (std::fetestexcept(kNonfiniteExceptions) == 0) return false;
  std::feclearexcept(kNonfiniteExceptions);
  return true;
#endif
}

}  // namespace tickfx
