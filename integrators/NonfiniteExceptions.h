// Arithmetic on finite values makes a value that is not finite only through an operation that
// raises a floating-point exception: invalid (inf − inf, 0 · inf, 0/0 give NaN), overflow or
// division by zero (±inf). The flags of these exceptions are sticky and per thread, and the
// hardware sets them for free (MXCSR on x86, FPSR on AArch64). So a loop whose inputs are all
// finite can be checked by testing the flags once it is done, with no operation per value; an
// input that is already NaN or infinite spreads without raising anything, so the inputs have to
// be known finite some other way (NonfiniteCheck::steppedRowsFinite()).
#pragma once

#include <cfenv>

namespace tickfx {

/// FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO. Inexact and underflow are left alone: they are the
/// ordinary life of finite arithmetic.
inline constexpr int kNonfiniteExceptions = FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO;

/// Whether some kNonfiniteExceptions flag is raised on this thread; clears them if so. Raised
/// flags may be older than the loop being checked (code before it on the thread): the caller's
/// answer to them (an exact scan) must be harmless when nothing is wrong.
inline bool takeNonfiniteExceptions() {
  if (std::fetestexcept(kNonfiniteExceptions) == 0) return false;
  std::feclearexcept(kNonfiniteExceptions);
  return true;
}

}  // namespace tickfx
